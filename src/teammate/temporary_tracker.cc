#include "swarmlio/teammate/temporary_tracker.h"

namespace swarmlio::teammate {

TemporaryTracker::TemporaryTracker(int id, int64_t stamp_ns, const Eigen::Vector3d& p_in_G,
                                   const TemporaryTrackerOptions& options, int trajectory_capacity)
    : id_(id), created_ns_(stamp_ns), last_update_ns_(stamp_ns), trajectory_(trajectory_capacity) {
  filter_.Initialize(stamp_ns, p_in_G, Eigen::Vector3d::Zero(), options.filter.lidar_position_sigma_m,
                     options.filter.initial_velocity_sigma_m_s);
  trajectory_.Push(stamp_ns, p_in_G);
}

TemporaryTracker::TemporaryTracker(int id, int64_t stamp_ns, const ConstantVelocityFilter& filter,
                                   const TrajectoryBuffer& trajectory)
    : id_(id),
      created_ns_(stamp_ns),
      last_update_ns_(stamp_ns),
      filter_(filter),
      trajectory_(trajectory) {}

void TemporaryTracker::Update(int64_t stamp_ns, const Eigen::Vector3d& p_in_G,
                              const TemporaryTrackerOptions& options) {
  filter_.PredictTo(stamp_ns, options.filter.accel_noise_density_m_s2_sqrt_hz);
  const double sigma = options.filter.lidar_position_sigma_m;
  filter_.Update(p_in_G, sigma * sigma * Eigen::Matrix3d::Identity());
  last_update_ns_ = stamp_ns;
  trajectory_.Push(stamp_ns, filter_.p());
}

}  // namespace swarmlio::teammate
