// The message types the bag reader decodes, by type name and encoding: ROS1
// names ("sensor_msgs/Imu") serialized as ROS1 ("ros1"), ROS 2 names
// ("sensor_msgs/msg/Imu") serialized as CDR ("cdr"). The same kind gives the
// same record either way (the decoders take the WireEncoding).
#pragma once

#include <string>

#include "src/io/ros_message_reader.h"

namespace swarmlio::io::internal {

inline constexpr char kRos1Encoding[] = "ros1";
inline constexpr char kCdrEncoding[] = "cdr";

inline constexpr char kRos2ImuType[] = "sensor_msgs/msg/Imu";
inline constexpr char kRos2PointCloud2Type[] = "sensor_msgs/msg/PointCloud2";
inline constexpr char kRos2CustomMsgType[] = "livox_ros_driver2/msg/CustomMsg";
inline constexpr char kRos2PoseStampedType[] = "geometry_msgs/msg/PoseStamped";
inline constexpr char kRos2OdometryType[] = "nav_msgs/msg/Odometry";

enum class MessageKind {
  kUnsupported,
  kImu,
  kPointCloud2,
  kLivoxCustomMsg,
  kPoseStamped,
  kOdometry
};

/// The kind of `datatype` in `encoding` ("ros1" or "cdr"), and its wire
/// encoding; kUnsupported for any other pair (a ROS 2 name in "ros1" too).
MessageKind MessageKindOf(const std::string& datatype,
                          const std::string& encoding,
                          WireEncoding* wire);

/// The MD5 sum a ROS1-encoded message of `kind` must carry ("" for
/// kUnsupported). CDR messages have none: ROS 2 logs carry no MD5.
std::string ExpectedRos1Md5(MessageKind kind);

}  // namespace swarmlio::io::internal
