// Options of the ROS1 bag reader and writer (see docs/bag_format.md).
//
// Both structs follow common/option_fields.h: in-class defaults, one
// VisitFields() that describes every field, and Validate() ("" when valid).
#pragma once

#include <array>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sensors/lidar_formats.h"

namespace swarmlio::io {

/// Chunk compression of a written bag: ROS1 bags take none, lz4 (ROS's own
/// LZ4 format) and bz2; MCAP files none, lz4 (LZ4 frames) and zstd.
enum class BagCompression { kNone, kLz4, kBz2, kZstd };

/// Container format of a written bag. kAuto: MCAP when the path ends in
/// ".mcap", else ROS1.
enum class BagFormat { kAuto, kRos1, kMcap, kDb3 };

/// Topic option value (or "") that finds the topic by its message type.
inline constexpr char kAutoTopic[] = "auto";

/// True for "" and "auto" (for imu_topic / lidar_topic) or "auto" (for
/// ground_truth_topic, where "" means none).
inline bool IsAutoTopic(const std::string& topic) { return topic.empty() || topic == kAutoTopic; }

/// Message type of written ground-truth poses.
enum class GroundTruthFormat { kPoseStamped, kOdometry };

/// What to do with a PointCloud2 scan that has no per-point time field.
///   kAuto:    reconstruct from azimuth when spinning_lidar, else one instant
///   kAzimuth: reconstruct from azimuth (any sensor)
///   kNone:    read the scan as one instant (all offsets 0)
enum class PointTimeReconstruction { kAuto, kAzimuth, kNone };

struct BagReaderOptions {
  // Topics. IMU and LiDAR: "" or "auto" finds the topic by message type, and
  // so does a configured topic that the bag lacks, when exactly one topic of
  // the bag has a matching type (else the error lists the candidates).
  // Ground truth: "" = none, "auto" = the only PoseStamped/Odometry topic; a
  // configured ground-truth topic that the bag lacks means no ground truth
  // (an odometry topic may be an estimate, so it is not taken silently).
  std::string imu_topic = "/livox/imu";      // sensor_msgs/Imu; required
  std::string lidar_topic = "/livox/lidar";  // PointCloud2 or Livox CustomMsg; required
  std::string ground_truth_topic = "/ground_truth/pose";  // PoseStamped or Odometry; optional
  TimestampUnit point_time_unit = TimestampUnit::kMicrosecond;
  std::string point_time_field;          // "" = auto: "time", "t", "timestamp", "offset_time"
  bool check_point_time_span = true;     // a per-point time span that cannot be a scan: error
  // Clouds without a per-point time field (docs/bag_format.md).
  PointTimeReconstruction reconstruct_point_time = PointTimeReconstruction::kAuto;
  bool spinning_lidar = false;  // the LiDAR spins (lidar.type: spinning; set by the manifest)
  bool skip_malformed_messages = false;  // false: a malformed message is an error
  bool verify_chunks = true;             // check every chunk's records on open (one extra pass)
  bool recover_damaged_bags = true;      // read truncated / unindexed bags by a record scan
  int max_message_mib = 512;             // larger messages are treated as corrupt [MiB]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    v("imu_topic", imu_topic,
      config::FieldSpec::Doc("sensor_msgs/Imu topic (required); \"\" or \"auto\" = the bag's only "
                             "sensor_msgs/Imu topic, also used when the topic is absent"));
    v("lidar_topic", lidar_topic,
      config::FieldSpec::Doc("sensor_msgs/PointCloud2 or livox_ros_driver(2)/CustomMsg topic "
                             "(required); \"\" or \"auto\" = the bag's only such topic, also "
                             "used when the topic is absent"));
    v("ground_truth_topic", ground_truth_topic,
      config::FieldSpec::Doc("geometry_msgs/PoseStamped or nav_msgs/Odometry topic (optional, may "
                             "be absent); \"\" = none, \"auto\" = the bag's only such topic"));
    v("point_time_unit", point_time_unit,
      config::FieldSpec::Doc("unit of the PointCloud2 per-point time field"));
    v("point_time_field", point_time_field,
      config::FieldSpec::Doc("PointCloud2 per-point time field name; empty = auto-detect "
                             "time/t/timestamp/offset_time"));
    v("check_point_time_span", check_point_time_span,
      config::FieldSpec::Doc("fail when a scan's per-point times span far more (or, with a "
                             "coarser unit fitting, far less) than the scan period in "
                             "point_time_unit: a wrong unit"));
    v("reconstruct_point_time", reconstruct_point_time,
      config::FieldSpec::Doc("PointCloud2 without a per-point time field: auto (from azimuth "
                             "when spinning_lidar, else one instant), azimuth (time = azimuth "
                             "swept since the first point / 360 deg * scan period) or none "
                             "(one instant)"));
    v("spinning_lidar", spinning_lidar,
      config::FieldSpec::Doc("the LiDAR is a spinning one (the replay manifest sets it from "
                             "lidar.type: spinning); selects azimuth for reconstruct_point_time: "
                             "auto"));
    v("skip_malformed_messages", skip_malformed_messages,
      config::FieldSpec::Doc("skip and count undecodable messages instead of failing"));
    v("verify_chunks", verify_chunks,
      config::FieldSpec::Doc("check every chunk's message records when opening (one extra "
                             "pass over the file); guards rosbag against corrupt bags"));
    v("recover_damaged_bags", recover_damaged_bags,
      config::FieldSpec::Doc("read a truncated or unindexed bag by scanning its records (every "
                             "complete message before the damage; the rest is counted); false: "
                             "such a bag is an error"));
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
  bool write_point_time = true;  // PointCloud2 only; false: no per-point time field (old drivers)
  GroundTruthFormat ground_truth_format = GroundTruthFormat::kPoseStamped;
  BagCompression compression = BagCompression::kNone;
  BagFormat format = BagFormat::kAuto;

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    v("imu_topic", imu_topic, config::FieldSpec::Doc("sensor_msgs/Imu topic"));
    v("lidar_topic", lidar_topic, config::FieldSpec::Doc("LiDAR topic"));
    v("ground_truth_topic", ground_truth_topic, config::FieldSpec::Doc("ground-truth topic"));
    v("lidar_format", lidar_format, config::FieldSpec::Doc("message type of LiDAR scans"));
    v("point_time_unit", point_time_unit,
      config::FieldSpec::Doc("unit of the written PointCloud2 time field"));
    v("point_time_field", point_time_field,
      config::FieldSpec::Doc("name of the written PointCloud2 time field"));
    v("write_point_time", write_point_time,
      config::FieldSpec::Doc("write the PointCloud2 per-point time field (false: clouds without "
                             "per-point time, as some drivers publish them)"));
    v("ground_truth_format", ground_truth_format,
      config::FieldSpec::Doc("message type of ground-truth poses"));
    v("compression", compression,
      config::FieldSpec::Doc("chunk compression: none, lz4 or bz2 (ROS1), none, lz4 or zstd "
                             "(MCAP)"));
    v("format", format,
      config::FieldSpec::Doc("auto (by the path: .mcap, .db3, else ROS1), ros1, mcap or db3 "
                             "(ROS 2 CDR messages in MCAP or in a rosbag2 SQLite file)"));
  }

  std::string Validate() const;
};

/// `format`, or for kAuto the format of `path` (MCAP for ".mcap", rosbag2
/// SQLite for ".db3", else ROS1).
BagFormat ResolveBagFormat(BagFormat format, const std::string& path);

/// "" when `compression` suits `format` (kAuto: any), else the error.
std::string CheckCompressionFor(BagFormat format, BagCompression compression);

}  // namespace swarmlio::io

namespace swarmlio::config {

template <>
struct EnumTraits<io::GroundTruthFormat> {
  static constexpr std::array<std::pair<io::GroundTruthFormat, const char*>, 2> kNames{{
      {io::GroundTruthFormat::kPoseStamped, "pose_stamped"},
      {io::GroundTruthFormat::kOdometry, "odometry"},
  }};
};

template <>
struct EnumTraits<io::PointTimeReconstruction> {
  static constexpr std::array<std::pair<io::PointTimeReconstruction, const char*>, 3> kNames{{
      {io::PointTimeReconstruction::kAuto, "auto"},
      {io::PointTimeReconstruction::kAzimuth, "azimuth"},
      {io::PointTimeReconstruction::kNone, "none"},
  }};
};

template <>
struct EnumTraits<io::BagCompression> {
  static constexpr std::array<std::pair<io::BagCompression, const char*>, 4> kNames{{
      {io::BagCompression::kNone, "none"},
      {io::BagCompression::kLz4, "lz4"},
      {io::BagCompression::kBz2, "bz2"},
      {io::BagCompression::kZstd, "zstd"},
  }};
};

template <>
struct EnumTraits<io::BagFormat> {
  static constexpr std::array<std::pair<io::BagFormat, const char*>, 4> kNames{{
      {io::BagFormat::kAuto, "auto"},
      {io::BagFormat::kRos1, "ros1"},
      {io::BagFormat::kMcap, "mcap"},
      {io::BagFormat::kDb3, "db3"},
  }};
};

}  // namespace swarmlio::config
