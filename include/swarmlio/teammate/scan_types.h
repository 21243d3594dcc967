// Inputs and intermediate types of the teammate detector (docs/teammate.md).
//
// Frames (docs/conventions.md): b_i = the observing drone's body (IMU) frame
// at the scan stamp, G_i its global frame, G_j a teammate's global frame.
// Times are double seconds in the observing drone's clock.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace swarmlio::teammate {

/// One LiDAR return handed to the detector: already in the body frame at the
/// scan stamp (motion-compensated by the caller), with its reflectivity and
/// the time it was captured, relative to that stamp.
struct ScanPoint {
  Eigen::Vector3f p_in_b = Eigen::Vector3f::Zero();  // [m]
  float reflectivity = 0.f;                          // Livox 0-255 scale
  float time_offset_s = 0.f;  // capture time - scan stamp [s] (<= 0 when the stamp is the scan end)
};

/// A Euclidean cluster of scan points, summarised.
struct PointCluster {
  Eigen::Vector3d centroid_in_b = Eigen::Vector3d::Zero();  // mean of the points [m]
  Eigen::Vector3d min_in_b = Eigen::Vector3d::Zero();       // bounding box [m]
  Eigen::Vector3d max_in_b = Eigen::Vector3d::Zero();
  double mean_time_offset_s = 0.0;  // mean capture time - scan stamp [s]
  int num_points = 0;
  int num_reflective_points = 0;  // points above the reflectivity threshold
  // Mean and mean capture time of the reflective points only (the tape);
  // valid when num_reflective_points > 0.
  Eigen::Vector3d reflective_centroid_in_b = Eigen::Vector3d::Zero();
  double reflective_mean_time_offset_s = 0.0;

  /// Bounding-box diagonal [m] (the size test of the field reference).
  double SizeM() const { return (max_in_b - min_in_b).norm(); }
};

/// One odometry message a teammate broadcasts (its ego state in its own
/// global frame G_j). The stamp must already be in the receiver's clock
/// (the network layer corrects the clock offset; docs/teammate.md).
struct TeammateOdometry {
  int64_t stamp_ns = 0;
  int drone_id = -1;
  Eigen::Vector3d p_bj_in_Gj = Eigen::Vector3d::Zero();   // [m]
  Eigen::Quaterniond q_Gj_bj = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_bj_in_Gj = Eigen::Vector3d::Zero();   // [m/s]
  /// The sender's last scan was LiDAR-degenerate: its odometry may drift, so
  /// its tracker predicts from the LiDAR track instead (teammate_tracker.h).
  bool degenerate = false;
};

}  // namespace swarmlio::teammate
