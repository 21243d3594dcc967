// Raw sensor records as they come from a log or the simulator, before any
// estimator processing. Time stamps are integer nanoseconds so that logs
// round-trip bit for bit; ToSeconds() (common/time.h) gives the double for
// computation.
//
// Frames: IMU samples are in the IMU frame; LiDAR points are in the LiDAR
// frame; a ground-truth pose is the IMU (body) frame b in a global frame G.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/time.h"

namespace swarmlio {


/// One IMU sample. Acceleration is the specific force as the device reports
/// it (m/s^2 for most IMUs, g for Livox built-in IMUs; the estimator's IMU
/// options say which), angular rate in rad/s.
struct ImuSample {
  int64_t stamp_ns = 0;
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();
  std::string frame_id;
};

/// One LiDAR return in the LiDAR frame.
struct LidarPoint {
  float x = 0.f;  // [m]
  float y = 0.f;  // [m]
  float z = 0.f;  // [m]
  float reflectivity = 0.f;  // Livox 0-255 scale (intensity for other sensors)
  double offset_time_s = 0.0;  // time of this point relative to the scan stamp [s]
  uint8_t tag = 0;   // Livox tag byte (0 when unknown)
  uint8_t line = 0;  // laser / ring index
};

/// One LiDAR frame. `stamp_ns` is the scan start (the ROS header stamp);
/// each point's absolute time is stamp + offset_time_s.
struct LidarScan {
  int64_t stamp_ns = 0;
  std::string frame_id;
  uint64_t livox_timebase_ns = 0;  // Livox CustomMsg timebase (0 when not Livox)
  uint8_t livox_lidar_id = 0;
  std::vector<LidarPoint> points;
};

/// A pose of the body (IMU) frame b in a global frame G.
struct PoseStamped {
  int64_t stamp_ns = 0;
  std::string frame_id;
  Eigen::Quaterniond q_G_b = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_b_in_G = Eigen::Vector3d::Zero();
};

}  // namespace swarmlio
