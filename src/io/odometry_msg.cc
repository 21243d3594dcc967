#include "src/io/odometry_msg.h"

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/Vector3.h>

namespace swarmlio::io::internal {
namespace {

// nav_msgs/msg/Odometry.msg of ROS1 (noetic), verbatim (the first line ends
// in two spaces).
constexpr char kOdometryText[] =
    "# This represents an estimate of a position and velocity in free space.  \n"
    "# The pose in this message should be specified in the coordinate frame given by "
    "header.frame_id.\n"
    "# The twist in this message should be specified in the coordinate frame given by the "
    "child_frame_id\n"
    "Header header\n"
    "string child_frame_id\n"
    "geometry_msgs/PoseWithCovariance pose\n"
    "geometry_msgs/TwistWithCovariance twist\n";

const std::string& Separator() {
  static const std::string* const kSeparator = new std::string(80, '=');
  return *kSeparator;
}

// A message's own text: its full definition up to its first "MSG:" section.
template <class M>
std::string OwnText() {
  const std::string full = ros::message_traits::Definition<M>::value();
  const size_t end = full.find("\n" + Separator() + "\nMSG: ");
  return end == std::string::npos ? full : full.substr(0, end);
}

template <class M>
void AppendSection(std::string* text) {
  *text += "\n" + Separator() + "\nMSG: " + ros::message_traits::DataType<M>::value() + "\n";
  *text += OwnText<M>();
}

std::string BuildNavOdometryDefinition() {
  std::string text = kOdometryText;
  AppendSection<std_msgs::Header>(&text);
  AppendSection<geometry_msgs::PoseWithCovariance>(&text);
  AppendSection<geometry_msgs::Pose>(&text);
  AppendSection<geometry_msgs::Point>(&text);
  AppendSection<geometry_msgs::Quaternion>(&text);
  AppendSection<geometry_msgs::TwistWithCovariance>(&text);
  AppendSection<geometry_msgs::Twist>(&text);
  AppendSection<geometry_msgs::Vector3>(&text);
  return text;
}

}  // namespace

const std::string& NavOdometryDefinition() {
  static const std::string* const kDefinition = new std::string(BuildNavOdometryDefinition());
  return *kDefinition;
}

}  // namespace swarmlio::io::internal
