// Summary of a ROS1 bag from its index (no message is decoded).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::io {

struct BagTopicInfo {
  std::string topic;
  std::string datatype;  // e.g. "sensor_msgs/Imu"
  std::string md5sum;
  int64_t message_count = 0;
  int64_t first_time_ns = 0;  // bag (receive) time of the first message
  int64_t last_time_ns = 0;   // bag (receive) time of the last message
};

struct BagInfo {
  std::string path;
  uint64_t file_size_bytes = 0;
  int64_t message_count = 0;
  int64_t start_time_ns = 0;         // bag time of the first message (0 if empty)
  int64_t end_time_ns = 0;           // bag time of the last message (0 if empty)
  std::vector<BagTopicInfo> topics;  // sorted by topic name
};

/// Reads the index of the bag at `path`.
Status ReadBagInfo(const std::string& path, BagInfo* info);

}  // namespace swarmlio::io
