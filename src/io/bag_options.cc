#include "swarmlio/io/bag_options.h"

namespace swarmlio::io {
namespace {

const char* const kWrittenFieldNames[] = {"x", "y", "z", "intensity", "tag", "line"};

std::string CheckTopic(const char* key, const std::string& topic, bool required) {
  if (required && topic.empty()) return std::string(key) + ": must not be empty";
  return {};
}

}  // namespace

std::string BagReaderOptions::Validate() const {
  // Empty or "auto" topics are found by type when the bag is opened.
  std::string error = config::ValidateFields(*this);
  if (error.empty() && !IsAutoTopic(imu_topic) && imu_topic == lidar_topic) {
    error = "lidar_topic: must differ from imu_topic '" + imu_topic + "'";
  }
  if (error.empty() && !IsAutoTopic(ground_truth_topic) &&
      (ground_truth_topic == imu_topic || ground_truth_topic == lidar_topic)) {
    error = "ground_truth_topic: must differ from imu_topic and lidar_topic";
  }
  return error;
}

std::string CheckCompressionFor(BagFormat format, BagCompression compression) {
  if (format == BagFormat::kRos1 && compression == BagCompression::kZstd) {
    return "compression: zstd is for MCAP files (ROS1 bags: none, lz4, bz2)";
  }
  if (format == BagFormat::kMcap && compression == BagCompression::kBz2) {
    return "compression: bz2 is for ROS1 bags (MCAP files: none, lz4, zstd)";
  }
  if (format == BagFormat::kDb3 && compression != BagCompression::kNone) {
    return "compression: rosbag2 .db3 files are written uncompressed (none)";
  }
  return "";
}

BagFormat ResolveBagFormat(BagFormat format, const std::string& path) {
  if (format != BagFormat::kAuto) return format;
  const auto ends_with = [&path](const std::string& extension) {
    return path.size() >= extension.size() &&
           path.compare(path.size() - extension.size(), extension.size(), extension) == 0;
  };
  if (ends_with(".mcap")) return BagFormat::kMcap;
  return ends_with(".db3") ? BagFormat::kDb3 : BagFormat::kRos1;
}

std::string BagWriterOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (error.empty()) error = CheckTopic("imu_topic", imu_topic, true);
  if (error.empty()) error = CheckTopic("lidar_topic", lidar_topic, true);
  if (error.empty()) error = CheckTopic("ground_truth_topic", ground_truth_topic, true);
  if (error.empty() && (imu_topic == lidar_topic || imu_topic == ground_truth_topic ||
                        lidar_topic == ground_truth_topic)) {
    error = "imu_topic, lidar_topic, ground_truth_topic: must be distinct";
  }
  if (error.empty() && point_time_field.empty()) error = "point_time_field: must not be empty";
  if (error.empty()) error = CheckCompressionFor(format, compression);
  for (const char* name : kWrittenFieldNames) {
    if (error.empty() && point_time_field == name) {
      error = "point_time_field: '" + point_time_field + "' clashes with a written point field";
    }
  }
  return error;
}

}  // namespace swarmlio::io
