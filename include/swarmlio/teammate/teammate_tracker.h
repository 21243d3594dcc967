// A teammate tracker (paper Sec. III-D-1): an identified teammate j, tracked
// in G_i with the constant-velocity filter, but
//  - predicted with the velocity j broadcasts, rotated by R_Gi_Gj;
//  - updated from a LiDAR cluster when j is seen, otherwise from j's
//    broadcast position mapped through the global extrinsic T_Gi_Gj;
//  - except while j reports its LiDAR degenerate (its odometry drifts): then
//    the filter runs on its own constant-velocity model and LiDAR updates
//    only, so that a drifting broadcast cannot pull the track off the drone.
// Swarm-LIO2 trusts the broadcast odometry more than the cluster for this
// filter (0.001 vs 0.01 m^2); the filter only predicts where to look, the
// observation output is the cluster itself (observation.h).
#pragma once

#include <Eigen/Core>
#include <string>

#include "swarmlio/common/time.h"
#include "swarmlio/common/option_fields.h"
#include "swarmlio/teammate/cv_filter.h"
#include "swarmlio/teammate/odometry_history.h"
#include "swarmlio/teammate/trajectory_buffer.h"

namespace swarmlio::teammate {

/// YAML section `teammate.teammate`.
struct TeammateTrackerOptions {
  double lidar_position_sigma_m = 0.1;      // cluster measurement 1-sigma (0.01 m^2)
  double odometry_position_sigma_m = 0.03;  // broadcast position 1-sigma (0.001 m^2)
  double velocity_sigma_m_s = 0.1;          // 1-sigma of the broadcast velocity in prediction
  double max_odometry_age_s = 0.5;          // older broadcasts are not used to update
  double disconnect_s = 2.0;                // no message for this long: the tracker holds still
  double degenerate_accel_noise_m_s2_sqrt_hz = 2.0;  // CV model while j reports degeneracy

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("lidar_position_sigma_m", lidar_position_sigma_m,
      FieldSpec::Positive("m", "1-sigma of a cluster position in the teammate filter"));
    v("odometry_position_sigma_m", odometry_position_sigma_m,
      FieldSpec::Positive("m", "1-sigma of the broadcast position through T_Gi_Gj"));
    v("velocity_sigma_m_s", velocity_sigma_m_s,
      FieldSpec::Positive("m/s", "1-sigma of the broadcast velocity used to predict"));
    v("max_odometry_age_s", max_odometry_age_s,
      FieldSpec::Positive("s", "broadcast older than this is stale (not used to update)"));
    v("disconnect_s", disconnect_s,
      FieldSpec::Positive("s", "no broadcast for this long: prediction stops"));
    v("degenerate_accel_noise_m_s2_sqrt_hz", degenerate_accel_noise_m_s2_sqrt_hz,
      FieldSpec::Positive("m/s^2/sqrt(Hz)",
                          "constant-velocity model noise while the teammate reports degeneracy"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

class TeammateTracker {
 public:
  /// Takes over a temporary tracker's filter after identification.
  /// `trajectory_capacity`: cluster positions kept (seen_trajectory()).
  TeammateTracker(int drone_id, int tracker_id, const Eigen::Matrix3d& R_Gi_Gj,
                  const Eigen::Vector3d& p_Gj_in_Gi, const ConstantVelocityFilter& filter,
                  int trajectory_capacity = 300);

  int drone_id() const { return drone_id_; }
  int tracker_id() const { return tracker_id_; }
  const Eigen::Matrix3d& R_Gi_Gj() const { return R_Gi_Gj_; }
  const Eigen::Vector3d& p_Gj_in_Gi() const { return p_Gj_in_Gi_; }
  void SetGlobalExtrinsic(const Eigen::Matrix3d& R_Gi_Gj, const Eigen::Vector3d& p_Gj_in_Gi) {
    R_Gi_Gj_ = R_Gi_Gj;
    p_Gj_in_Gi_ = p_Gj_in_Gi;
  }

  /// The teammate's velocity in G_i at `stamp_ns` from its broadcasts (the
  /// newest one while connected); false when disconnected.
  bool VelocityInGi(int64_t stamp_ns, const OdometryHistory& history,
                    const TeammateTrackerOptions& options, Eigen::Vector3d* v_in_Gi) const;

  /// Moves the filter to `stamp_ns` with the broadcast velocity.
  void Predict(int64_t stamp_ns, const OdometryHistory& history, const TeammateTrackerOptions& options);
  /// Predicted position at `stamp_ns` (state unchanged).
  Eigen::Vector3d PositionAt(int64_t stamp_ns, const OdometryHistory& history,
                             const TeammateTrackerOptions& options) const;

  /// LiDAR update with a cluster position measured at `stamp_ns`.
  void UpdateLidar(int64_t stamp_ns, const Eigen::Vector3d& p_in_Gi, const OdometryHistory& history,
                   const TeammateTrackerOptions& options);
  /// Update with the broadcast position at `stamp_ns` mapped into G_i; false
  /// (no update, prediction only) when the broadcast is stale.
  bool UpdateOdometry(int64_t stamp_ns, const OdometryHistory& history,
                      const TeammateTrackerOptions& options);

  const ConstantVelocityFilter& filter() const { return filter_; }
  /// The cluster positions of its LiDAR updates (G_i, newest last): when
  /// the teammate restarts, a temporary tracker continues with them.
  const TrajectoryBuffer& seen_trajectory() const { return seen_; }

 private:
  int drone_id_;
  int tracker_id_;
  Eigen::Matrix3d R_Gi_Gj_;
  Eigen::Vector3d p_Gj_in_Gi_;
  ConstantVelocityFilter filter_;
  TrajectoryBuffer seen_;
};

}  // namespace swarmlio::teammate
