// Builds a Trajectory from a flight plan: a static start (IMU initialisation),
// then take-off, hover, transit and seeded random-excitation segments.
//
// Each segment appends control points of the quintic B-spline (see
// trajectory.h). Transits follow a quintic smoothstep so the speed limit is
// respected; excitation visits random targets inside a box around the
// position where it starts. Deterministic for a given seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

struct TrajectoryBuilderOptions {
  double knot_interval_s = 0.5;      // B-spline knot spacing [s]
  double max_speed_m_s = 1.5;        // transit speed limit [m/s]
  double max_yaw_rate_rad_s = 0.8;   // transit yaw-rate limit [rad/s]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("knot_interval_s", knot_interval_s, FieldSpec::Positive("s", "B-spline knot spacing"));
    v("max_speed_m_s", max_speed_m_s, FieldSpec::Positive("m/s", "transit speed limit"));
    v("max_yaw_rate_rad_s", max_yaw_rate_rad_s,
      FieldSpec::Positive("rad/s", "transit yaw-rate limit"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

class TrajectoryBuilder {
 public:
  TrajectoryBuilder(const Eigen::Vector3d& start_p_in_W, double start_yaw_rad,
                    const TrajectoryBuilderOptions& options, uint64_t seed);

  /// Stays exactly still for `duration_s` (a hover that starts at rest).
  void Hover(double duration_s);
  /// Climbs vertically by `height_m`.
  void Takeoff(double height_m);
  /// Flies to `target_in_W` while turning to `yaw_rad`; the duration follows
  /// from the speed and yaw-rate limits (at least `min_duration_s`).
  void TransitTo(const Eigen::Vector3d& target_in_W, double yaw_rad, double min_duration_s = 0.0);
  /// Random flight for `duration_s` around the current position: a new target
  /// in [-amplitude, amplitude] per axis and yaw within +-yaw_amplitude every
  /// `period_s`; returns to the start position at the end.
  void Excite(double duration_s, const Eigen::Vector3d& amplitude_m, double yaw_amplitude_rad,
              double period_s);

  /// Current end position/yaw of the plan.
  Eigen::Vector3d position() const { return points_.back().head<3>(); }
  double yaw() const { return points_.back()[3]; }
  /// Planned duration so far [s] (from start_time).
  double duration() const;

  /// The trajectory, padded with a hover so that it lasts at least
  /// `min_duration_s`; it starts at `start_time_s`.
  Trajectory Build(double start_time_s, double min_duration_s,
                   AttitudeMode mode = AttitudeMode::kQuadrotor) const;

 private:
  void MoveTo(const Eigen::Vector4d& target, int num_knots);
  int KnotsFor(double duration_s) const;

  TrajectoryBuilderOptions options_;
  std::mt19937_64 rng_;
  std::vector<Eigen::Vector4d> points_;
};

}  // namespace swarmlio::sim
