// Checks shared by the bag reader and the single-message decoder
// (sensor_message_codec.h): finite values, non-finite points removed, the
// Livox CustomMsg type names.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

// The Livox drivers 1 and 2 use the same CustomMsg layout (and MD5).
inline constexpr std::array<const char*, 2> kCustomMsgTypes = {"livox_ros_driver/CustomMsg",
                                                               "livox_ros_driver2/CustomMsg"};

inline bool IsCustomMsgType(const std::string& datatype) {
  for (const char* custom : kCustomMsgTypes) {
    if (datatype == custom) return true;
  }
  return false;
}

inline bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

inline bool PointFinite(const LidarPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) &&
         std::isfinite(p.offset_time_s);
}

// Removes non-finite points; returns how many were removed.
inline int64_t DropNonFinitePoints(LidarScan* scan) {
  std::vector<LidarPoint>& points = scan->points;
  const size_t before = points.size();
  size_t kept = 0;
  for (size_t i = 0; i < before; ++i) {
    if (PointFinite(points[i])) {
      if (kept != i) points[kept] = points[i];
      ++kept;
    }
  }
  points.resize(kept);
  return static_cast<int64_t>(before - kept);
}

}  // namespace swarmlio::io::internal
