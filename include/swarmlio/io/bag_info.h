// Summary of a ROS1 bag from its index, of an MCAP file from a scan of its
// data section, of a rosbag2 .db3 file or folder from its tables (no message
// is decoded). A truncated or unindexed bag is
// summarized from a scan of its records (recovery).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/io/read_stats.h"

namespace swarmlio::io {

struct BagTopicInfo {
  std::string topic;
  std::string datatype;  // e.g. "sensor_msgs/Imu" (ROS 2 in MCAP: "sensor_msgs/msg/Imu")
  std::string md5sum;    // ROS1 only
  std::string encoding;  // message encoding: "ros1", or an MCAP channel's ("cdr")
  int64_t message_count = 0;
  int64_t first_time_ns = 0;  // bag (receive) time of the first message
  int64_t last_time_ns = 0;   // bag (receive) time of the last message
};

struct BagInfo {
  std::string path;
  std::string format;  // "ros1", "mcap", "db3" (told by the magic bytes) or "rosbag2" (a folder)
  uint64_t file_size_bytes = 0;
  int64_t message_count = 0;
  int64_t start_time_ns = 0;         // bag time of the first message (0 if empty)
  int64_t end_time_ns = 0;           // bag time of the last message (0 if empty)
  std::vector<BagTopicInfo> topics;  // sorted by topic name
  BagRecoveryStats recovery;         // set when the bag is truncated or unindexed
};

/// Reads the index of the bag at `path`. A truncated or unindexed bag is
/// scanned instead (info->recovery says what was found and what was lost),
/// unless `recover_damaged_bags` is false: then it is an error.
Status ReadBagInfo(const std::string& path, BagInfo* info, bool recover_damaged_bags = true);

}  // namespace swarmlio::io
