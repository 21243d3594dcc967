// RosInput: the ROS node's sensor subscriptions (docs/online.md, "ROS node").
// Both topics are subscribed as raw messages (topic_tools::ShapeShifter), so
// a Livox CustomMsg needs no generated message package: the bytes are
// decoded by the project's own decoders (io::SensorMessageDecoder, the bag
// reader's) and the records pushed into the LiveDrone's PushSource, which
// orders the two streams (stamp order, or IMU first: --ordering). The LiDAR type (Livox CustomMsg of
// driver 1 or 2, or PointCloud2) is taken from the first message.
#pragma once

#include <ros/ros.h>
#include <topic_tools/shape_shifter.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "swarmlio/io/sensor_message_codec.h"
#include "swarmlio/live/push_source.h"

namespace swarmlio::tools {

struct RosInputOptions {
  std::string imu_topic = "/livox/imu";      // sensor_msgs/Imu
  std::string lidar_topic = "/livox/lidar";  // Livox CustomMsg or sensor_msgs/PointCloud2
  int imu_queue = 2000;    // subscriber queue [messages]: 10 s at 200 Hz (nothing is dropped
                           // while the callbacks keep up)
  int lidar_queue = 50;    // [messages]: 5 s at 10 Hz
  bool tcp_nodelay = true; // no Nagle delay on the sensor connections

  /// "" when valid.
  std::string Validate() const;
};

struct RosInputStats {
  int64_t imu_messages = 0;
  int64_t lidar_messages = 0;
  int64_t imu_pushed = 0;
  int64_t scans_pushed = 0;
  int64_t rejected = 0;       // wrong type / MD5, undecodable (first reason in first_error)
  std::string first_error;
};

class RosInput {
 public:
  /// Subscribes on `node` (topics resolved in its namespace). `decode`:
  /// point-time options as for a bag; `scan_period_s` [s] the LiDAR's
  /// nominal period. `source` (not owned) receives the records.
  RosInput(ros::NodeHandle* node, const RosInputOptions& options,
           const io::BagReaderOptions& decode, double scan_period_s, live::PushSource* source);

  /// Any thread. Wall-clock time of the last message [ns since epoch] (0:
  /// none yet), for an idle timeout.
  int64_t last_message_wall_ns() const { return last_message_wall_ns_.load(); }
  RosInputStats stats() const;
  /// The decoders' skip counts (read after the subscriptions stopped).
  io::ReadStats read_stats() const;

 private:
  void OnImu(const topic_tools::ShapeShifter::ConstPtr& message);
  void OnLidar(const topic_tools::ShapeShifter::ConstPtr& message);
  // Copies the message's serialized bytes into `buffer`.
  static void Bytes(const topic_tools::ShapeShifter& message, std::vector<uint8_t>* buffer);
  void Reject(const std::string& reason);
  void Touch();

  live::PushSource* source_;
  io::SensorMessageDecoder decoder_;
  ros::Subscriber imu_subscriber_;
  ros::Subscriber lidar_subscriber_;
  std::vector<uint8_t> imu_bytes_;
  std::vector<uint8_t> lidar_bytes_;
  std::atomic<int64_t> last_message_wall_ns_{0};
  mutable std::mutex mutex_;  // stats_
  RosInputStats stats_;
};

}  // namespace swarmlio::tools
