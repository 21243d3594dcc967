// RosInput: raw sensor messages -> decoded records -> PushSource (ros_input.h).
#include "ros_input.h"

#include <chrono>
#include <utility>

namespace swarmlio::tools {

std::string RosInputOptions::Validate() const {
  if (imu_topic.empty() || imu_topic == io::kAutoTopic) return "imu_topic: a topic name is needed";
  if (lidar_topic.empty() || lidar_topic == io::kAutoTopic) {
    return "lidar_topic: a topic name is needed";
  }
  if (imu_queue < 1 || lidar_queue < 1) return "imu_queue, lidar_queue: at least 1";
  return "";
}

RosInput::RosInput(ros::NodeHandle* node, const RosInputOptions& options,
                   const io::BagReaderOptions& decode, double scan_period_s,
                   live::PushSource* source)
    : source_(source), decoder_(decode, scan_period_s) {
  ros::TransportHints hints;
  if (options.tcp_nodelay) hints = hints.tcpNoDelay();
  imu_subscriber_ = node->subscribe<topic_tools::ShapeShifter>(
      options.imu_topic, static_cast<uint32_t>(options.imu_queue), &RosInput::OnImu, this, hints);
  lidar_subscriber_ = node->subscribe<topic_tools::ShapeShifter>(
      options.lidar_topic, static_cast<uint32_t>(options.lidar_queue), &RosInput::OnLidar, this,
      hints);
}

RosInputStats RosInput::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

io::ReadStats RosInput::read_stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return decoder_.stats();
}

void RosInput::Bytes(const topic_tools::ShapeShifter& message, std::vector<uint8_t>* buffer) {
  buffer->resize(message.size());
  ros::serialization::OStream stream(buffer->data(), static_cast<uint32_t>(buffer->size()));
  message.write(stream);
}

void RosInput::Reject(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stats_.rejected == 0) stats_.first_error = reason;
  ++stats_.rejected;
}

void RosInput::Touch() {
  last_message_wall_ns_ = std::chrono::duration_cast<std::chrono::nanoseconds>(
                              std::chrono::system_clock::now().time_since_epoch())
                              .count();
}

void RosInput::OnImu(const topic_tools::ShapeShifter::ConstPtr& message) {
  Touch();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.imu_messages;
  }
  const std::string& type = message->getDataType();
  if (type != "sensor_msgs/Imu" || message->getMD5Sum() != io::ExpectedMd5(type)) {
    Reject("IMU topic: " + type + " [" + message->getMD5Sum() + "], expected sensor_msgs/Imu");
    return;
  }
  Bytes(*message, &imu_bytes_);
  ImuSample imu;
  bool accepted = false;
  Status status;
  {
    std::lock_guard<std::mutex> lock(mutex_);  // the decoder's stats
    status = decoder_.DecodeImu(imu_bytes_.data(), imu_bytes_.size(), &imu, &accepted);
    if (status.ok() && accepted) ++stats_.imu_pushed;
  }
  if (!status.ok()) return Reject("IMU topic: " + status.message());
  if (accepted) source_->PushImu(imu);
}

void RosInput::OnLidar(const topic_tools::ShapeShifter::ConstPtr& message) {
  Touch();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.lidar_messages;
  }
  const std::string& type = message->getDataType();
  io::LidarMessageType lidar_type;
  if (!io::LidarMessageTypeFromDatatype(type, &lidar_type) ||
      message->getMD5Sum() != io::ExpectedMd5(type)) {
    Reject("LiDAR topic: " + type + " [" + message->getMD5Sum() +
           "], expected livox_ros_driver(2)/CustomMsg or sensor_msgs/PointCloud2");
    return;
  }
  Bytes(*message, &lidar_bytes_);
  LidarScan scan;
  bool accepted = false;
  Status status;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status = decoder_.DecodeScan(lidar_type, lidar_bytes_.data(), lidar_bytes_.size(), &scan,
                                 &accepted);
    if (status.ok() && accepted) ++stats_.scans_pushed;
  }
  if (!status.ok()) return Reject("LiDAR topic: " + status.message());
  if (accepted) source_->PushScan(std::move(scan));
}

}  // namespace swarmlio::tools
