// How a drone's odometry initializes (YAML `odometry.initialization` and
// `odometry.in_flight`; docs/imu.md, "Initialization in flight").
#pragma once

#include <array>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::lio {

/// static: the IMU window must pass the static test; the state starts at
/// rest (v = 0, g = -mean specific force) and the window's scans seed the
/// map. in_flight: velocity and gravity come from LiDAR passes over the first
/// scans (the drone may move from the first sample on).
enum class InitializationMode { kStatic, kInFlight };

struct InFlightInitOptions {
  // Scans ending within this time after the start t0 are registered in each
  // pass; their positions fit v0 and g [s].
  double probe_duration_s = 1.5;
  // Passes over those scans: the first from the coarse guess (v = 0, g = the
  // mean specific force), each next from the previous fit; the last fit starts
  // the odometry, which then processes the buffered scans with the teammates.
  int passes = 3;
  double coarse_velocity_stddev_m_s = 2.0;  // first pass: 1-sigma of v = 0 [m/s]
  double coarse_gravity_stddev_m_s2 = 3.0;  // first pass: 1-sigma of the coarse g [m/s^2]
  // Prior of b_g (0 in the first pass, then the pass's estimate): no static
  // mean to take it from; the simulated Avia's built-in IMU has 0.07 rad/s [rad/s].
  double gyro_bias_stddev_rad_s = 0.05;
  double position_stddev_floor_m = 0.01;    // least sigma of a fitted scan position [m]
  double velocity_stddev_floor_m_s = 0.02;  // added to the fitted velocity sigma [m/s]
  double gravity_stddev_floor_m_s2 = 0.02;  // added to the fitted gravity sigma [m/s^2]
  double max_rms_residual_m = 0.1;          // worse fit: the initialization starts over [m]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("probe_duration_s", probe_duration_s,
      FieldSpec::InRange(0.3, 10.0, "s", "scans after the start used to fit velocity and gravity"));
    v("passes", passes, FieldSpec::InRange(1.0, 10.0, "", "LiDAR passes over those scans"));
    v("coarse_velocity_stddev_m_s", coarse_velocity_stddev_m_s,
      FieldSpec::Positive("m/s", "first pass: 1-sigma of the velocity guess 0"));
    v("coarse_gravity_stddev_m_s2", coarse_gravity_stddev_m_s2,
      FieldSpec::Positive("m/s^2",
                          "first pass: 1-sigma of the gravity guess (mean specific force)"));
    v("gyro_bias_stddev_rad_s", gyro_bias_stddev_rad_s,
      FieldSpec::Positive("rad/s", "1-sigma of the gyro-bias prior 0"));
    v("position_stddev_floor_m", position_stddev_floor_m,
      FieldSpec::Positive("m", "least 1-sigma of a fitted scan position"));
    v("velocity_stddev_floor_m_s", velocity_stddev_floor_m_s,
      FieldSpec::Positive("m/s", "added to the fitted velocity 1-sigma"));
    v("gravity_stddev_floor_m_s2", gravity_stddev_floor_m_s2,
      FieldSpec::Positive("m/s^2", "added to the fitted gravity 1-sigma"));
    v("max_rms_residual_m", max_rms_residual_m,
      FieldSpec::Positive("m",
                          "rms residual of the fit above which the initialization starts over"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

}  // namespace swarmlio::lio

namespace swarmlio::config {

template <>
struct EnumTraits<lio::InitializationMode> {
  static constexpr std::array<std::pair<lio::InitializationMode, const char*>, 2> kNames{{
      {lio::InitializationMode::kStatic, "static"},
      {lio::InitializationMode::kInFlight, "in_flight"},
  }};
};

}  // namespace swarmlio::config
