// Ground truth: geometry_msgs/PoseStamped and nav_msgs/Odometry (its pose
// part) <-> PoseStamped (body frame b in global frame G).
#pragma once

#include <geometry_msgs/PoseStamped.h>

#include <cstddef>
#include <cstdint>

#include "src/io/odometry_msg.h"
#include "src/io/ros_message_reader.h"
#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

/// Decodes the serialized bytes of one geometry_msgs/PoseStamped (ROS1, or
/// ROS 2 CDR for geometry_msgs/msg/PoseStamped; the same for Odometry). The
/// quaternion is taken as stored (not normalized).
Status DecodePoseStamped(const uint8_t* data,
                         size_t size,
                         PoseStamped* pose,
                         WireEncoding encoding = WireEncoding::kRos1);

Status EncodePoseStamped(const PoseStamped& pose, uint32_t seq, geometry_msgs::PoseStamped* msg);

/// Decodes the serialized bytes of one nav_msgs/Odometry: header and
/// pose.pose (quaternion as stored); child_frame_id, the covariances and the
/// twist are checked for length and skipped.
Status DecodeOdometryPose(const uint8_t* data,
                          size_t size,
                          PoseStamped* pose,
                          WireEncoding encoding = WireEncoding::kRos1);

/// An Odometry with the pose, child_frame_id "body", zero twist and
/// covariances.
Status EncodeOdometry(const PoseStamped& pose, uint32_t seq, NavOdometry* msg);

}  // namespace swarmlio::io::internal
