#include "src/io/message_types.h"

#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include "src/io/custom_msg.h"
#include "src/io/odometry_msg.h"
#include "src/io/record_checks.h"

namespace swarmlio::io::internal {
namespace {

template <class Msg>
const char* Ros1Name() {
  return ros::message_traits::DataType<Msg>::value();
}

MessageKind Ros1Kind(const std::string& datatype) {
  if (datatype == Ros1Name<sensor_msgs::Imu>()) return MessageKind::kImu;
  if (datatype == Ros1Name<sensor_msgs::PointCloud2>()) return MessageKind::kPointCloud2;
  if (IsCustomMsgType(datatype)) return MessageKind::kLivoxCustomMsg;
  if (datatype == Ros1Name<geometry_msgs::PoseStamped>()) return MessageKind::kPoseStamped;
  if (datatype == kNavOdometryDataType) return MessageKind::kOdometry;
  return MessageKind::kUnsupported;
}

MessageKind Ros2Kind(const std::string& datatype) {
  if (datatype == kRos2ImuType) return MessageKind::kImu;
  if (datatype == kRos2PointCloud2Type) return MessageKind::kPointCloud2;
  if (datatype == kRos2CustomMsgType) return MessageKind::kLivoxCustomMsg;
  if (datatype == kRos2PoseStampedType) return MessageKind::kPoseStamped;
  if (datatype == kRos2OdometryType) return MessageKind::kOdometry;
  return MessageKind::kUnsupported;
}

}  // namespace

MessageKind MessageKindOf(const std::string& datatype,
                          const std::string& encoding,
                          WireEncoding* wire) {
  if (encoding == kRos1Encoding) {
    *wire = WireEncoding::kRos1;
    return Ros1Kind(datatype);
  }
  if (encoding == kCdrEncoding) {
    *wire = WireEncoding::kCdr;
    return Ros2Kind(datatype);
  }
  return MessageKind::kUnsupported;
}

std::string ExpectedRos1Md5(MessageKind kind) {
  switch (kind) {
    case MessageKind::kImu:
      return ros::message_traits::MD5Sum<sensor_msgs::Imu>::value();
    case MessageKind::kPointCloud2:
      return ros::message_traits::MD5Sum<sensor_msgs::PointCloud2>::value();
    case MessageKind::kLivoxCustomMsg:
      return kLivoxCustomMsgMd5;
    case MessageKind::kPoseStamped:
      return ros::message_traits::MD5Sum<geometry_msgs::PoseStamped>::value();
    case MessageKind::kOdometry:
      return kNavOdometryMd5;
    case MessageKind::kUnsupported:
      break;
  }
  return "";
}

}  // namespace swarmlio::io::internal
