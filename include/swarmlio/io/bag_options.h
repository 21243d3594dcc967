// Options of the ROS1 bag reader and writer (see docs/bag_format.md).
//
// Both structs follow config/option_fields.h: in-class defaults, one
// VisitFields() that describes every field, and Validate() ("" when valid).
#pragma once

#include <array>
#include <string>
#include <utility>

#include "swarmlio/config/option_fields.h"
#include "swarmlio/sensors/lidar_formats.h"

namespace swarmlio::io {

/// Chunk compression of a written bag.
enum class BagCompression { kNone, kLz4, kBz2 };

struct BagReaderOptions {
  std::string imu_topic = "/livox/imu";      // sensor_msgs/Imu; must exist
  std::string lidar_topic = "/livox/lidar";  // PointCloud2 or Livox CustomMsg; must exist
  std::string ground_truth_topic = "/ground_truth/pose";  // geometry_msgs/PoseStamped; optional
  TimestampUnit point_time_unit = TimestampUnit::kMicrosecond;
  std::string point_time_field;          // "" = auto: "time", "t", "timestamp", "offset_time"
  bool skip_malformed_messages = false;  // false: a malformed message is an error
  bool verify_chunks = true;             // check every chunk's records on open (one extra pass)
  int max_message_mib = 512;             // larger messages are treated as corrupt [MiB]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    v("imu_topic", imu_topic, config::FieldSpec::Doc("sensor_msgs/Imu topic (required)"));
    v("lidar_topic", lidar_topic,
      config::FieldSpec::Doc("sensor_msgs/PointCloud2 or livox_ros_driver/CustomMsg topic "
                             "(required)"));
    v("ground_truth_topic", ground_truth_topic,
      config::FieldSpec::Doc("geometry_msgs/PoseStamped topic (optional, may be absent)"));
    v("point_time_unit", point_time_unit,
      config::FieldSpec::Doc("unit of the PointCloud2 per-point time field"));
    v("point_time_field", point_time_field,
      config::FieldSpec::Doc("PointCloud2 per-point time field name; empty = auto-detect "
                             "time/t/timestamp/offset_time"));
    v("skip_malformed_messages", skip_malformed_messages,
      config::FieldSpec::Doc("skip and count undecodable messages instead of failing"));
    v("verify_chunks", verify_chunks,
      config::FieldSpec::Doc("check every chunk's message records when opening (one extra "
                             "pass over the file); guards rosbag against corrupt bags"));
    v("max_message_mib", max_message_mib,
      config::FieldSpec::InRange(1, 4096, "MiB", "larger messages are rejected as corrupt"));
  }

  std::string Validate() const;
};

struct BagWriterOptions {
  std::string imu_topic = "/livox/imu";
  std::string lidar_topic = "/livox/lidar";
  std::string ground_truth_topic = "/ground_truth/pose";
  LidarMessageFormat lidar_format = LidarMessageFormat::kLivoxCustomMsg;
  TimestampUnit point_time_unit = TimestampUnit::kMicrosecond;  // PointCloud2 only
  std::string point_time_field = "time";                        // PointCloud2 only
  BagCompression compression = BagCompression::kNone;

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    v("imu_topic", imu_topic, config::FieldSpec::Doc("sensor_msgs/Imu topic"));
    v("lidar_topic", lidar_topic, config::FieldSpec::Doc("LiDAR topic"));
    v("ground_truth_topic", ground_truth_topic,
      config::FieldSpec::Doc("geometry_msgs/PoseStamped topic"));
    v("lidar_format", lidar_format, config::FieldSpec::Doc("message type of LiDAR scans"));
    v("point_time_unit", point_time_unit,
      config::FieldSpec::Doc("unit of the written PointCloud2 time field"));
    v("point_time_field", point_time_field,
      config::FieldSpec::Doc("name of the written PointCloud2 time field"));
    v("compression", compression, config::FieldSpec::Doc("bag chunk compression"));
  }

  std::string Validate() const;
};

}  // namespace swarmlio::io

namespace swarmlio::config {

template <>
struct EnumTraits<io::BagCompression> {
  static constexpr std::array<std::pair<io::BagCompression, const char*>, 3> kNames{{
      {io::BagCompression::kNone, "none"},
      {io::BagCompression::kLz4, "lz4"},
      {io::BagCompression::kBz2, "bz2"},
  }};
};

}  // namespace swarmlio::config
