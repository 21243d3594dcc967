// Velocity and gravity of a drone that starts its estimator in flight
// (docs/imu.md, "Initialization in flight"), from the positions a LiDAR pass
// over the first scans gave and the IMU samples since the start.
//
// G is the IMU frame at the start t0 (R_G_b(t0) = I, p_b_in_G(t0) = 0). With
// the rotation R_G_b(t) integrated from the gyro (bias b_g) and the specific
// force f(t) = k a_m(t) (b_a = 0, as at a static start), the position is
//
//   p_b_in_G(t) = v0 tau + 1/2 g tau^2 + D(t),  tau = t - t0,
//   D(t) = int_t0^t int_t0^s R_G_b(u) f(u) du ds,
//
// linear in the unknowns x = [v0; g_in_G] (6). R_G_b(t) is re-anchored at
// every scan pose to the pass's rotation estimate R_k (LiDAR-corrected) and
// integrated from the gyro only between scans, so an unknown gyro bias (the
// Avia's built-in IMU: 0.07 rad/s, 4 deg over 1 s) tilts little. Each scan pose p_k gives three
// rows [tau_k I, tau_k^2/2 I] x = p_k - D(t_k); x is the least-squares
// solution (QR). Its covariance is sigma^2 (A^T A)^-1 with sigma the rms
// residual per coordinate, floored (the poses of a first pass are not
// independent, so the floor keeps the sigma honest). D is integrated with the
// propagator's midpoint rule, sub-stepped at the pose stamps.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::lio {

/// A pose of the body at a stamp, in G (a pass's posterior at a scan end).
/// The fit uses its position; the rotation re-anchors the integration. (Not
/// PoseStamped of sensors/measurements.h, which carries a frame_id string.)
struct StampedPose {
  int64_t stamp_ns = 0;
  Eigen::Vector3d p_b_in_G = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_G_b = Eigen::Quaterniond::Identity();
};

struct VelocityGravityAlignment {
  Eigen::Vector3d v_b_in_G = Eigen::Vector3d::Zero();  // at t0 [m/s]
  Eigen::Vector3d g_in_G = Eigen::Vector3d::Zero();    // [m/s^2]
  /// Covariance of [v; g] (6x6, SI units).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double rms_residual_m = 0.0;  // per coordinate
  int num_positions = 0;
};

/// Double integral D(t_k) of the rotated specific force from `start` (the
/// sample at t0, the frame G) over `samples` (stamps after t0, increasing),
/// at every pose stamp of `poses` (increasing, in (t0, last sample]); the
/// rotation restarts from each pose's q_G_b there.
/// acceleration_to_m_s2: the signed unit factor k. InvalidArgument on
/// stamps outside the samples.
Status DoubleIntegrateSpecificForce(const ImuSample& start,
                                    const std::vector<ImuSample>& samples,
                                    double acceleration_to_m_s2,
                                    const Eigen::Vector3d& gyro_bias_rad_s,
                                    const std::vector<StampedPose>& poses,
                                    std::vector<Eigen::Vector3d>* double_integrals);

/// The least-squares v0 and g above. FailedPrecondition with fewer than 3
/// positions or a span under 0.2 s (g is not separable from v0).
Status AlignVelocityAndGravity(const ImuSample& start,
                               const std::vector<ImuSample>& samples,
                               double acceleration_to_m_s2,
                               const Eigen::Vector3d& gyro_bias_rad_s,
                               const std::vector<StampedPose>& positions,
                               double position_stddev_floor_m,
                               VelocityGravityAlignment* result);

}  // namespace swarmlio::lio
