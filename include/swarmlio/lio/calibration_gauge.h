// The LiDAR-IMU calibration's error seen in G. The first scan anchors the map
// through the calibrated extrinsic (R_imu_lidar, p_lidar_in_imu_m): a
// rotation error dtheta of the calibration rotates the whole map, and with it
// every later pose, about the LiDAR's position at that scan, and a
// translation error dt shifts the map by R_G_b0 dt. The map is not in the
// filter's state, so the filter's covariance is relative to its own map; the
// position covariance in G adds the map's:
//
//   d = p_b_in_G - p_lidar0_in_G,  M = [d]x R_G_b0 + R_G_b [p_lidar_in_imu]x
//   Sigma_G = P_pp + sigma_r^2 M M^T + sigma_t^2 (R_G_b0 - R_G_b)(R_G_b0 - R_G_b)^T
//
// To first order, a rotation error e (in the LiDAR frame, R_given =
// R_true Exp(e)) and a translation error dt move the estimated IMU position
// by -M R_imu_lidar e + (R_G_b0 - R_G_b) dt: the map rotates by
// R_G_b0 R_imu_lidar e about the first LiDAR position and shifts by
// R_G_b0 dt, and the IMU position is the LiDAR's minus the lever arm
// (derivation: docs/lio.md "Covariance in G"; e and dt isotropic, so
// R_imu_lidar drops out). A teammate relates its map to
// this drone's through T_Gi_Gj, which absorbs the map's rotation and shift,
// so the broadcast carries the filter's covariance, not this one
// (docs/lio.md "Covariance in G").
#pragma once

#include <Eigen/Core>

namespace swarmlio::lio {

struct CalibrationUncertainty {
  double rotation_sigma_rad = 0.0;   // 1-sigma per axis of R_imu_lidar [rad]
  double translation_sigma_m = 0.0;  // 1-sigma per axis of p_lidar_in_imu_m [m]
};

/// Where the map was anchored: the body attitude of the first scan and the
/// LiDAR's position then, in G, and the calibrated lever arm.
struct MapAnchor {
  Eigen::Matrix3d R_G_b0 = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_lidar0_in_G = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_lidar_in_imu_m = Eigen::Vector3d::Zero();
};

/// The covariance the calibration's uncertainty adds to p_b_in_G [m^2].
Eigen::Matrix3d CalibrationGaugeCovariance(const CalibrationUncertainty& calibration,
                                           const MapAnchor& anchor,
                                           const Eigen::Matrix3d& R_G_b,
                                           const Eigen::Vector3d& p_b_in_G);

}  // namespace swarmlio::lio
