// Motion compensation of one LiDAR scan (docs/imu.md, "Undistortion").
//
// Every point, measured in the LiDAR frame at t = scan.stamp + offset_time_s,
// is moved to the body (IMU) frame at the scan END, the time of the last pose
// of `poses` (ImuPropagator::scan_poses() after PropagateTo(scan end)):
//
//   p_in_b(t)     = R_imu_lidar p_in_L + p_lidar_in_imu
//   T_G_b(t)      from the pose i with t_i <= t < t_{i+1}, tau = t - t_i:
//                   R(t) = R_i Exp(w_i tau),  p(t) = p_i + v_i tau + a_i tau^2 / 2
//                   (constant acceleration a_i in G and rate w_i, exactly the
//                   propagation model, so p(t_{i+1}) = p_{i+1})
//   p_in_b_end    = R_e^T (R(t) p_in_b(t) + p(t) - p_e)
//
// Points before the first pose (or after the last) are extrapolated with the
// first (last) pose's held input and counted.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/voxel_filter.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::lio {

/// A motion-compensated point: body (IMU) frame at the scan end time.
struct UndistortedPoint {
  Eigen::Vector3d p_in_b_end = Eigen::Vector3d::Zero();  // [m]
  float reflectivity = 0.f;                              // copied from the LiDAR point
  double offset_time_s = 0.0;  // original time relative to the scan stamp [s]
  uint8_t tag = 0;
  uint8_t line = 0;
};

struct UndistortionStats {
  int64_t end_stamp_ns = 0;  // the time the points were moved to
  int num_points = 0;        // points written
  int num_extrapolated = 0;  // points outside [first pose, last pose]
  int num_skipped_non_finite = 0;
};

/// Pose of the body at `stamp_ns` + `offset_s` from the piecewise model
/// above (poses sorted by time, non-empty).
void BodyPoseAt(const std::vector<ImuPose>& poses,
                int64_t stamp_ns,
                double offset_s,
                Eigen::Matrix3d* R_G_b,
                Eigen::Vector3d* p_b_in_G);

/// Moves every finite point of `scan` to the body frame at the end pose.
/// R_imu_lidar must be a rotation (e.g. LidarOptions::QuaternionImuLidar()).
/// FailedPrecondition when `poses` is empty, InvalidArgument when the poses
/// are not sorted by time. The output keeps the input order.
Status UndistortScan(const LidarScan& scan,
                     const std::vector<ImuPose>& poses,
                     const Eigen::Matrix3d& R_imu_lidar,
                     const Eigen::Vector3d& p_lidar_in_imu_m,
                     std::vector<UndistortedPoint>* points,
                     UndistortionStats* stats = nullptr);

/// The same motion compensation for points already in the body frame (the
/// output of lio::Preprocess, times relative to `scan_stamp_ns`): writes
/// p_in_b_end for each point, in input order, into `*points_in_b_end`.
Status UndistortPoints(const std::vector<lio::PointXYZT>& points_in_b,
                       int64_t scan_stamp_ns,
                       const std::vector<ImuPose>& poses,
                       std::vector<Eigen::Vector3d>* points_in_b_end,
                       UndistortionStats* stats = nullptr);

}  // namespace swarmlio::lio
