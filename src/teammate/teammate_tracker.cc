#include "swarmlio/teammate/teammate_tracker.h"

#include "swarmlio/common/time.h"

#include <cmath>

namespace swarmlio::teammate {

TeammateTracker::TeammateTracker(int drone_id, int tracker_id, const Eigen::Matrix3d& R_Gi_Gj,
                                 const Eigen::Vector3d& p_Gj_in_Gi,
                                 const ConstantVelocityFilter& filter, int trajectory_capacity)
    : drone_id_(drone_id),
      tracker_id_(tracker_id),
      R_Gi_Gj_(R_Gi_Gj),
      p_Gj_in_Gi_(p_Gj_in_Gi),
      filter_(filter),
      seen_(trajectory_capacity) {}

namespace {

// j's newest broadcast says its LiDAR is degenerate: do not use its odometry.
bool ReportsDegeneracy(const OdometryHistory& history) {
  return !history.empty() && history.newest().degenerate;
}

}  // namespace

bool TeammateTracker::VelocityInGi(int64_t stamp_ns, const OdometryHistory& history,
                                   const TeammateTrackerOptions& options,
                                   Eigen::Vector3d* v_in_Gi) const {
  if (ReportsDegeneracy(history)) {
    *v_in_Gi = filter_.v();
    return true;
  }
  if (history.empty() || SecondsBetween(history.newest().stamp_ns, stamp_ns) > options.disconnect_s) return false;
  Eigen::Vector3d p_bj_in_Gj, v_bj_in_Gj;
  if (!history.StateAt(stamp_ns, options.max_odometry_age_s, options.max_odometry_age_s,
                       &p_bj_in_Gj, &v_bj_in_Gj)) {
    v_bj_in_Gj = history.newest().v_bj_in_Gj;
  }
  *v_in_Gi = R_Gi_Gj_ * v_bj_in_Gj;
  return true;
}

void TeammateTracker::Predict(int64_t stamp_ns, const OdometryHistory& history,
                              const TeammateTrackerOptions& options) {
  if (ReportsDegeneracy(history)) {
    filter_.PredictTo(stamp_ns, options.degenerate_accel_noise_m_s2_sqrt_hz);
    return;
  }
  Eigen::Vector3d v_in_Gi;
  if (!VelocityInGi(stamp_ns, history, options, &v_in_Gi)) v_in_Gi.setZero();
  filter_.PredictWithVelocity(stamp_ns, v_in_Gi, options.velocity_sigma_m_s);
}

Eigen::Vector3d TeammateTracker::PositionAt(int64_t stamp_ns, const OdometryHistory& history,
                                            const TeammateTrackerOptions& options) const {
  Eigen::Vector3d v_in_Gi;
  if (!VelocityInGi(stamp_ns, history, options, &v_in_Gi)) return filter_.p();
  return filter_.p() + v_in_Gi * SecondsBetween(filter_.stamp_ns(), stamp_ns);
}

void TeammateTracker::UpdateLidar(int64_t stamp_ns, const Eigen::Vector3d& p_in_Gi,
                                  const OdometryHistory& history,
                                  const TeammateTrackerOptions& options) {
  Predict(stamp_ns, history, options);
  const double sigma = options.lidar_position_sigma_m;
  filter_.Update(p_in_Gi, sigma * sigma * Eigen::Matrix3d::Identity());
  seen_.Push(stamp_ns, p_in_Gi);
}

bool TeammateTracker::UpdateOdometry(int64_t stamp_ns, const OdometryHistory& history,
                                     const TeammateTrackerOptions& options) {
  Predict(stamp_ns, history, options);
  if (ReportsDegeneracy(history)) return false;
  Eigen::Vector3d p_bj_in_Gj;
  if (!history.StateAt(stamp_ns, options.max_odometry_age_s, options.max_odometry_age_s,
                       &p_bj_in_Gj, nullptr)) {
    return false;
  }
  const double sigma = options.odometry_position_sigma_m;
  filter_.Update(R_Gi_Gj_ * p_bj_in_Gj + p_Gj_in_Gi_, sigma * sigma * Eigen::Matrix3d::Identity());
  return true;
}

}  // namespace swarmlio::teammate
