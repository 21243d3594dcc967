// swarmlio_bag_publisher: publishes a drone's bag on ROS topics in real time,
// as the drone's drivers would (for swarmlio_ros, its test, and trying the
// node without a drone; docs/online.md "ROS node"). The bag is read with the
// project's BagReader (stamp order) and every IMU sample and scan is
// re-serialized as the bag writer writes it (Livox CustomMsg or
// PointCloud2, the bag's type) and published at its header stamp's time
// (x --rate), the stamps unchanged. --lidar_delay_s publishes each scan
// later, as a driver does at the scan end, so the IMU and LiDAR streams
// interleave differently from stamp order.
//
//   swarmlio_bag_publisher --bag=sim/uav1.bag --wait_for_subscribers_s=10
#include <gflags/gflags.h>
#include <ros/ros.h>
#include <topic_tools/shape_shifter.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/io/sensor_message_codec.h"

DEFINE_string(bag, "", "the bag to publish (IMU and LiDAR topics)");
DEFINE_string(imu_topic, "", "published IMU topic (default: the bag's)");
DEFINE_string(lidar_topic, "", "published LiDAR topic (default: the bag's)");
DEFINE_double(rate, 1.0, "speed (1 = real time)");
DEFINE_double(duration_s, 0.0, "publish only the bag's first seconds; 0 = all");
DEFINE_double(lidar_delay_s, 0.0,
              "publish each scan this much after its stamp (a driver publishing at the scan end) [s]");
DEFINE_double(wait_for_subscribers_s, 0.0,
              "first wait (at most this long) until both topics have a subscriber [s]");
DEFINE_int32(queue_size, 10000, "publisher queues [messages] (large: nothing is dropped)");

namespace swarmlio::tools {
namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "error: %s\n", message.c_str());
  return 1;
}

// The message types of the bag's records, from one serialization each.
Status MessageTypes(io::LidarMessageType lidar_type, io::RosMessageType* imu,
                    io::RosMessageType* lidar, io::BagWriterOptions* writer) {
  std::vector<uint8_t> bytes;
  SWARMLIO_RETURN_IF_ERROR(io::SerializeImu(ImuSample(), 0, &bytes, imu));
  writer->lidar_format = lidar_type == io::LidarMessageType::kLivoxCustomMsg
                             ? LidarMessageFormat::kLivoxCustomMsg
                             : LidarMessageFormat::kPointCloud2;
  return io::SerializeScan(LidarScan(), *writer, 0, &bytes, lidar);
}

void Publish(const ros::Publisher& publisher, const io::RosMessageType& type,
             std::vector<uint8_t>* bytes) {
  topic_tools::ShapeShifter message;
  message.morph(type.md5sum, type.datatype, type.definition, "false");
  ros::serialization::IStream stream(bytes->data(), static_cast<uint32_t>(bytes->size()));
  message.read(stream);
  publisher.publish(message);
}

void SleepUntil(const ros::WallTime& due) {
  const ros::WallTime now = ros::WallTime::now();
  if (due > now) (due - now).sleep();
}

// A scan waiting for its (delayed) publication time.
struct DelayedScan {
  ros::WallTime due;
  std::vector<uint8_t> bytes;
};

int Main() {
  if (FLAGS_bag.empty()) return Fail("--bag is required");
  if (!(FLAGS_rate > 0.0) || FLAGS_lidar_delay_s < 0.0) {
    return Fail("--rate must be > 0 and --lidar_delay_s >= 0");
  }
  io::BagReaderOptions reader_options;
  reader_options.imu_topic = io::kAutoTopic;
  reader_options.lidar_topic = io::kAutoTopic;
  reader_options.ground_truth_topic = "";
  std::unique_ptr<io::BagReader> reader;
  Status status = io::BagReader::Open(FLAGS_bag, reader_options, &reader);
  if (!status.ok()) return Fail(status.message());
  const std::string imu_topic = FLAGS_imu_topic.empty() ? reader->imu_topic() : FLAGS_imu_topic;
  const std::string lidar_topic =
      FLAGS_lidar_topic.empty() ? reader->lidar_topic() : FLAGS_lidar_topic;
  io::RosMessageType imu_type, lidar_type;
  io::BagWriterOptions writer;
  status = MessageTypes(reader->lidar_message_type(), &imu_type, &lidar_type, &writer);
  if (!status.ok()) return Fail(status.message());

  ros::NodeHandle node;
  const uint32_t queue = static_cast<uint32_t>(FLAGS_queue_size);
  ros::AdvertiseOptions imu_options(imu_topic, queue, imu_type.md5sum, imu_type.datatype,
                                    imu_type.definition);
  ros::AdvertiseOptions lidar_options(lidar_topic, queue, lidar_type.md5sum, lidar_type.datatype,
                                      lidar_type.definition);
  const ros::Publisher imu_publisher = node.advertise(imu_options);
  const ros::Publisher lidar_publisher = node.advertise(lidar_options);
  if (FLAGS_wait_for_subscribers_s > 0.0) {
    const ros::WallTime give_up =
        ros::WallTime::now() + ros::WallDuration(FLAGS_wait_for_subscribers_s);
    while (ros::ok() && ros::WallTime::now() < give_up &&
           (imu_publisher.getNumSubscribers() == 0 || lidar_publisher.getNumSubscribers() == 0)) {
      ros::WallDuration(0.01).sleep();
    }
    if (imu_publisher.getNumSubscribers() == 0 || lidar_publisher.getNumSubscribers() == 0) {
      return Fail("no subscriber on " + imu_topic + " and " + lidar_topic + " after " +
                  std::to_string(FLAGS_wait_for_subscribers_s) + " s");
    }
    ros::WallDuration(0.2).sleep();  // the subscribers' connections settle
  }

  io::BagRecord record;
  bool has = false;
  status = reader->Next(&record, &has);
  if (!status.ok()) return Fail(status.message());
  const int64_t first_ns = has ? record.stamp_ns() : 0;
  const int64_t end_ns = FLAGS_duration_s > 0.0
                             ? first_ns + static_cast<int64_t>(std::llround(FLAGS_duration_s * 1e9))
                             : INT64_MAX;
  const ros::WallTime start = ros::WallTime::now();
  auto due = [&](int64_t stamp_ns) {
    return start + ros::WallDuration(static_cast<double>(stamp_ns - first_ns) * 1e-9 / FLAGS_rate);
  };
  std::deque<DelayedScan> delayed;  // in due order
  int64_t imu_count = 0, scan_count = 0;
  // Publishes the delayed scans due by `until` (all: nullptr).
  auto publish_delayed = [&](const ros::WallTime* until) {
    while (!delayed.empty() && (until == nullptr || delayed.front().due <= *until) && ros::ok()) {
      SleepUntil(delayed.front().due);
      Publish(lidar_publisher, lidar_type, &delayed.front().bytes);
      delayed.pop_front();
      ++scan_count;
    }
  };
  uint32_t imu_seq = 0, scan_seq = 0;
  std::vector<uint8_t> bytes;
  io::RosMessageType type;
  while (has && record.stamp_ns() <= end_ns && ros::ok()) {
    const ros::WallTime record_due = due(record.stamp_ns());
    if (const ImuSample* imu = record.imu()) {
      status = io::SerializeImu(*imu, imu_seq++, &bytes, &type);
      if (!status.ok()) return Fail(status.message());
      publish_delayed(&record_due);
      SleepUntil(record_due);
      Publish(imu_publisher, imu_type, &bytes);
      ++imu_count;
    } else if (const LidarScan* scan = record.scan()) {
      DelayedScan d;
      status = io::SerializeScan(*scan, writer, scan_seq++, &d.bytes, &type);
      if (!status.ok()) return Fail(status.message());
      d.due = record_due + ros::WallDuration(FLAGS_lidar_delay_s);
      delayed.push_back(std::move(d));
      publish_delayed(&record_due);
    }
    status = reader->Next(&record, &has);
    if (!status.ok()) return Fail(status.message());
  }
  publish_delayed(nullptr);
  ros::WallDuration(1.0).sleep();  // the subscribers take the last messages
  std::printf("published %lld IMU samples on %s and %lld scans on %s\n",
              static_cast<long long>(imu_count), imu_topic.c_str(),
              static_cast<long long>(scan_count), lidar_topic.c_str());
  return 0;
}

}  // namespace
}  // namespace swarmlio::tools

int main(int argc, char** argv) {
  ros::init(argc, argv, "swarmlio_bag_publisher");
  gflags::SetUsageMessage("publishes a drone's bag on ROS topics in real time (docs/online.md)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  return swarmlio::tools::Main();
}
