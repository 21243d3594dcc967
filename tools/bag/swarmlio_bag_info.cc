// swarmlio_bag_info: prints the topics, message types, counts and time range
// of a ROS1 bag, an MCAP file or a rosbag2 .db3 file or folder (ROS 2; told
// by its magic bytes) (of a
// truncated or unindexed bag: what a scan of its records
// recovered and what was lost), then reads the IMU / LiDAR / ground-truth
// topics with BagReader (topics found by type when absent) and prints its
// statistics (delivered and skipped records).
//
//   swarmlio_bag_info [--imu_topic=...] [--lidar_topic=...] [--read=false] run.bag
//
// Exit code 0 on success, 1 if the bag cannot be read, 2 on bad usage.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <memory>
#include <string>

#include "swarmlio/io/bag_info.h"
#include "swarmlio/io/bag_reader.h"

DEFINE_string(bag, "", "bag file (or give it as the positional argument)");
DEFINE_string(imu_topic,
              "/livox/imu",
              "sensor_msgs/Imu topic; 'auto' or absent: the bag's only sensor_msgs/Imu topic");
DEFINE_string(lidar_topic,
              "/livox/lidar",
              "PointCloud2 or livox_ros_driver(2)/CustomMsg topic; 'auto' or absent: the bag's "
              "only such topic");
DEFINE_string(ground_truth_topic,
              "/ground_truth/pose",
              "geometry_msgs/PoseStamped or nav_msgs/Odometry topic (optional; 'auto': the "
              "bag's only such topic)");
DEFINE_string(point_time_unit, "us", "PointCloud2 per-point time unit: s, ms, us or ns");
DEFINE_string(point_time_field, "", "PointCloud2 per-point time field (empty = auto-detect)");
DEFINE_bool(read, true, "read the sensor topics and print reader statistics");
DEFINE_bool(skip_malformed_messages, false, "count undecodable messages instead of failing");
DEFINE_bool(recover_damaged_bags,
            true,
            "read a truncated or unindexed bag by scanning its records (false: an error)");
DEFINE_bool(check_point_time_span,
            true,
            "fail when PointCloud2 per-point times do not fit the scan period in "
            "--point_time_unit");

namespace {

using swarmlio::Status;
namespace io = swarmlio::io;

std::string FormatStamp(int64_t stamp_ns) {
  char text[48];
  const char* sign = stamp_ns < 0 ? "-" : "";
  const uint64_t magnitude =
      stamp_ns < 0 ? static_cast<uint64_t>(-(stamp_ns + 1)) + 1 : static_cast<uint64_t>(stamp_ns);
  std::snprintf(text, sizeof(text), "%s%" PRIu64 ".%09" PRIu64, sign, magnitude / 1000000000u,
                magnitude % 1000000000u);
  return text;
}

int Fail(const std::string& message) {
  std::fprintf(stderr, "swarmlio_bag_info: error: %s\n", message.c_str());
  return 1;
}

void PrintInfo(const io::BagInfo& info) {
  std::printf("path:      %s\n", info.path.c_str());
  std::printf("format:    %s\n", info.format == "ros1" ? "ROS1 bag" : info.format.c_str());
  std::printf("size:      %" PRIu64 " bytes (%.1f MiB)\n", info.file_size_bytes,
              static_cast<double>(info.file_size_bytes) / (1024.0 * 1024.0));
  std::printf("messages:  %" PRId64 "\n", info.message_count);
  if (info.message_count > 0) {
    std::printf("start:     %s s\n", FormatStamp(info.start_time_ns).c_str());
    std::printf("end:       %s s\n", FormatStamp(info.end_time_ns).c_str());
    std::printf("duration:  %s s\n", FormatStamp(info.end_time_ns - info.start_time_ns).c_str());
  }
  std::printf("topics:\n");
  size_t width = 0;
  for (const io::BagTopicInfo& t : info.topics) width = std::max(width, t.topic.size());
  for (const io::BagTopicInfo& t : info.topics) {
    const std::string type =
        t.encoding == "ros1" ? t.datatype : t.datatype + " (" + t.encoding + ")";
    std::printf("  %-*s %8" PRId64 " msgs  %s  [%s .. %s s]\n", static_cast<int>(width),
                t.topic.c_str(), t.message_count, type.c_str(),
                FormatStamp(t.first_time_ns).c_str(), FormatStamp(t.last_time_ns).c_str());
  }
  if (info.recovery.recovered) {
    std::printf("damaged:   %s\n", info.recovery.Summary().c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "prints topics, types, counts, time range and reader statistics of a "
      "ROS1 bag, MCAP file, rosbag2 .db3 file or folder\n  usage: swarmlio_bag_info [flags] "
      "<bag, .mcap, .db3 or rosbag2 folder>");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;

  std::string path = FLAGS_bag;
  if (argc == 2 && path.empty()) {
    path = argv[1];
  } else if (argc != 1 || path.empty()) {
    std::fprintf(stderr, "swarmlio_bag_info: error: give exactly one bag file\n%s\n",
                 gflags::ProgramUsage());
    return 2;
  }

  io::BagInfo info;
  Status status = io::ReadBagInfo(path, &info, FLAGS_recover_damaged_bags);
  if (!status.ok()) return Fail(status.message());
  PrintInfo(info);
  if (!FLAGS_read) return 0;

  io::BagReaderOptions options;
  options.imu_topic = FLAGS_imu_topic;
  options.lidar_topic = FLAGS_lidar_topic;
  options.ground_truth_topic = FLAGS_ground_truth_topic;
  options.point_time_field = FLAGS_point_time_field;
  options.skip_malformed_messages = FLAGS_skip_malformed_messages;
  options.recover_damaged_bags = FLAGS_recover_damaged_bags;
  options.check_point_time_span = FLAGS_check_point_time_span;
  if (!swarmlio::config::EnumFromString(FLAGS_point_time_unit, &options.point_time_unit)) {
    std::fprintf(stderr, "swarmlio_bag_info: error: --point_time_unit '%s' is not one of %s\n",
                 FLAGS_point_time_unit.c_str(),
                 swarmlio::config::EnumChoices<swarmlio::TimestampUnit>().c_str());
    return 2;
  }

  std::unique_ptr<io::BagReader> reader;
  status = io::BagReader::Open(path, options, &reader);
  if (!status.ok()) return Fail(status.message() + " (use --read=false to skip reading)");
  int64_t first_ns = 0;
  int64_t last_ns = 0;
  bool any = false;
  while (true) {
    io::BagRecord record;
    bool has_record = false;
    status = reader->Next(&record, &has_record);
    if (!status.ok() || !has_record) break;
    if (!any) first_ns = record.stamp_ns();
    last_ns = record.stamp_ns();
    any = true;
  }
  std::printf("reader (imu %s, lidar %s as %s, ground truth %s%s):\n", reader->imu_topic().c_str(),
              reader->lidar_topic().c_str(),
              reader->lidar_message_type() == io::LidarMessageType::kLivoxCustomMsg
                  ? "livox CustomMsg"
                  : "PointCloud2",
              reader->has_ground_truth() ? reader->ground_truth_topic().c_str() : "(none)",
              !reader->has_ground_truth() ? ""
              : reader->ground_truth_message_type() == io::GroundTruthMessageType::kOdometry
                  ? " as Odometry"
                  : " as PoseStamped");
  if (any) {
    std::printf("  stamps: %s .. %s s\n", FormatStamp(first_ns).c_str(),
                FormatStamp(last_ns).c_str());
  }
  std::string stats = reader->stats().ToString();
  for (size_t pos = 0; pos < stats.size();) {
    const size_t end = stats.find('\n', pos);
    std::printf("  %s\n", stats.substr(pos, end - pos).c_str());
    pos = end == std::string::npos ? stats.size() : end + 1;
  }
  if (!status.ok()) return Fail(status.message());
  return 0;
}
