// Our definition of nav_msgs/Odometry (Debian ships no nav_msgs headers),
// wire compatible with ROS1's: same datatype, MD5 and genmsg full
// definition text, so ground truth recorded as Odometry can be read, and
// written for tests and tools.
//
// Wire layout (little endian): std_msgs/Header header, string
// child_frame_id, geometry_msgs/PoseWithCovariance pose (Pose: float64
// position x y z, float64 orientation x y z w; float64[36] covariance),
// geometry_msgs/TwistWithCovariance twist (float64 linear x y z, angular
// x y z; float64[36] covariance).
#pragma once

#include <geometry_msgs/PoseWithCovariance.h>
#include <geometry_msgs/TwistWithCovariance.h>
#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <std_msgs/Header.h>

#include <string>

namespace swarmlio::io::internal {

inline constexpr char kNavOdometryDataType[] = "nav_msgs/Odometry";
inline constexpr char kNavOdometryMd5[] = "cd5e73d190d741a2f92e81eda573aca7";

struct NavOdometry {
  std_msgs::Header header;
  std::string child_frame_id;
  geometry_msgs::PoseWithCovariance pose;
  geometry_msgs::TwistWithCovariance twist;
};

/// The genmsg full definition: the Odometry text (verbatim from nav_msgs),
/// then "MSG:" sections for std_msgs/Header, geometry_msgs/PoseWithCovariance,
/// Pose, Point, Quaternion, TwistWithCovariance, Twist and Vector3 (genmsg's
/// depth-first dependency order), each section the installed message's own
/// text.
const std::string& NavOdometryDefinition();

}  // namespace swarmlio::io::internal

namespace ros {
namespace message_traits {

template <>
struct IsMessage<swarmlio::io::internal::NavOdometry> : TrueType {};
template <>
struct HasHeader<swarmlio::io::internal::NavOdometry> : TrueType {};

template <>
struct MD5Sum<swarmlio::io::internal::NavOdometry> {
  static const char* value() { return swarmlio::io::internal::kNavOdometryMd5; }
  static const char* value(const swarmlio::io::internal::NavOdometry&) { return value(); }
};
template <>
struct DataType<swarmlio::io::internal::NavOdometry> {
  static const char* value() { return swarmlio::io::internal::kNavOdometryDataType; }
  static const char* value(const swarmlio::io::internal::NavOdometry&) { return value(); }
};
template <>
struct Definition<swarmlio::io::internal::NavOdometry> {
  static const char* value() { return swarmlio::io::internal::NavOdometryDefinition().c_str(); }
  static const char* value(const swarmlio::io::internal::NavOdometry&) { return value(); }
};

}  // namespace message_traits

namespace serialization {

template <>
struct Serializer<swarmlio::io::internal::NavOdometry> {
  template <typename Stream, typename Msg>
  inline static void allInOne(Stream& stream, Msg& m) {
    stream.next(m.header);
    stream.next(m.child_frame_id);
    stream.next(m.pose);
    stream.next(m.twist);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};

}  // namespace serialization
}  // namespace ros
