// ROS 2 CDR serialization of the messages the bag writer writes, from the
// same ROS1 message structs the ROS1 path fills (imu_codec.h, pose_codec.h,
// pointcloud2_codec.h, custom_msg_codec.h), so both formats carry the same
// values; and the ROS 2 type names and "ros2msg" schema texts for MCAP.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <cstdint>
#include <string>
#include <vector>

#include "src/io/custom_msg.h"
#include "src/io/message_types.h"
#include "src/io/odometry_msg.h"

namespace swarmlio::io::internal {

void SerializeCdr(const sensor_msgs::Imu& msg, std::vector<uint8_t>* bytes);
void SerializeCdr(const sensor_msgs::PointCloud2& msg, std::vector<uint8_t>* bytes);
void SerializeCdr(const LivoxCustomMsg& msg, std::vector<uint8_t>* bytes);
void SerializeCdr(const geometry_msgs::PoseStamped& msg, std::vector<uint8_t>* bytes);
void SerializeCdr(const NavOdometry& msg, std::vector<uint8_t>* bytes);

/// The ROS 2 type name of `kind` ("sensor_msgs/msg/Imu", ...).
const char* Ros2TypeName(MessageKind kind);

/// The "ros2msg" schema text of `kind`: its field lines, then each nested
/// type after a line of 80 '=' and "MSG: <type>", as ROS 2 recorders write it.
const std::string& Ros2SchemaText(MessageKind kind);

}  // namespace swarmlio::io::internal
