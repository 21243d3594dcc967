#include "swarmlio/sim/trajectory_builder.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {
namespace {

// Quintic smoothstep: zero first and second derivative at both ends; peak slope 15/8.
double SmootherStep(double x) { return x * x * x * (x * (6.0 * x - 15.0) + 10.0); }
constexpr double kSmootherStepPeakSlope = 1.875;

}  // namespace

TrajectoryBuilder::TrajectoryBuilder(const Eigen::Vector3d& start_p_in_W, double start_yaw_rad,
                                     const TrajectoryBuilderOptions& options, uint64_t seed)
    : options_(options), rng_(seed) {
  CHECK_GT(options_.knot_interval_s, 0.0);
  CHECK_GT(options_.max_speed_m_s, 0.0);
  CHECK_GT(options_.max_yaw_rate_rad_s, 0.0);
  Eigen::Vector4d p0;
  p0 << start_p_in_W, start_yaw_rad;
  // Six equal control points: the curve starts at rest.
  points_.assign(6, p0);
}

int TrajectoryBuilder::KnotsFor(double duration_s) const {
  return std::max(0, static_cast<int>(std::ceil(duration_s / options_.knot_interval_s - 1e-9)));
}

double TrajectoryBuilder::duration() const {
  return static_cast<double>(points_.size() - 5) * options_.knot_interval_s;
}

void TrajectoryBuilder::Hover(double duration_s) {
  const Eigen::Vector4d last = points_.back();
  for (int k = 0; k < KnotsFor(duration_s); ++k) points_.push_back(last);
}

void TrajectoryBuilder::MoveTo(const Eigen::Vector4d& target, int num_knots) {
  const Eigen::Vector4d start = points_.back();
  for (int k = 1; k <= num_knots; ++k) {
    points_.push_back(start + (target - start) * SmootherStep(static_cast<double>(k) / num_knots));
  }
}

void TrajectoryBuilder::Takeoff(double height_m) {
  TransitTo(position() + Eigen::Vector3d(0, 0, height_m), yaw());
}

void TrajectoryBuilder::TransitTo(const Eigen::Vector3d& target_in_W, double yaw_rad,
                                  double min_duration_s) {
  const double dist = (target_in_W - position()).norm();
  const double dyaw = std::abs(yaw_rad - yaw());
  const double duration =
      std::max({min_duration_s, kSmootherStepPeakSlope * dist / options_.max_speed_m_s,
                kSmootherStepPeakSlope * dyaw / options_.max_yaw_rate_rad_s,
                4.0 * options_.knot_interval_s});
  Eigen::Vector4d target;
  target << target_in_W, yaw_rad;
  MoveTo(target, KnotsFor(duration));
}

void TrajectoryBuilder::Excite(double duration_s, const Eigen::Vector3d& amplitude_m,
                               double yaw_amplitude_rad, double period_s) {
  CHECK_GT(period_s, 0.0);
  const Eigen::Vector4d center = points_.back();
  const int knots_per_target = std::max(2, KnotsFor(period_s));
  const int total = KnotsFor(duration_s);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int used = 0;
  while (used + 2 * knots_per_target <= total) {
    Eigen::Vector4d target = center;
    for (int i = 0; i < 3; ++i) target[i] += amplitude_m[i] * unit(rng_);
    target[3] += yaw_amplitude_rad * unit(rng_);
    MoveTo(target, knots_per_target);
    used += knots_per_target;
  }
  MoveTo(center, std::max(2, total - used));
}

Trajectory TrajectoryBuilder::Build(double start_time_s, double min_duration_s,
                                    AttitudeMode mode) const {
  std::vector<Eigen::Vector4d> points = points_;
  // End at rest: six equal points, and long enough.
  for (int k = 0; k < 6; ++k) points.push_back(points_.back());
  while (static_cast<double>(points.size() - 5) * options_.knot_interval_s < min_duration_s) {
    points.push_back(points_.back());
  }
  return Trajectory(start_time_s, options_.knot_interval_s, std::move(points), mode);
}

}  // namespace swarmlio::sim
