#include "src/io/custom_msg.h"

namespace swarmlio::io::internal {
namespace {

// Message texts (comments are ours; only the field lines enter the MD5).
constexpr char kCustomMsgText[] =
    "# Livox point cloud frame.\n"
    "\n"
    "Header header           # stamp: time of the first point\n"
    "uint64 timebase         # time of the first point [ns]\n"
    "uint32 point_num        # number of points\n"
    "uint8 lidar_id          # LiDAR device id\n"
    "uint8[3] rsvd           # reserved\n"
    "CustomPoint[] points    # the points\n";

constexpr char kCustomPointText[] =
    "# One Livox return.\n"
    "\n"
    "uint32 offset_time      # time relative to timebase [ns]\n"
    "float32 x               # [m]\n"
    "float32 y               # [m]\n"
    "float32 z               # [m]\n"
    "uint8 reflectivity      # 0-255\n"
    "uint8 tag               # Livox tag\n"
    "uint8 line              # laser line\n";

std::string BuildLivoxCustomMsgDefinition() {
  // genmsg's full text: the message text, then for every dependency (in field
  // order) a separator line, "MSG: <type>" and the dependency's text, with
  // one blank line between the parts and no newline added at the very end.
  const std::string separator(80, '=');
  std::string text = kCustomMsgText;
  text += "\n" + separator + "\nMSG: std_msgs/Header\n";
  text += ros::message_traits::Definition<std_msgs::Header>::value();
  text += "\n" + separator + "\nMSG: " + std::string(kLivoxCustomPointDataType) + "\n";
  text += kCustomPointText;
  return text;
}

}  // namespace

const std::string& LivoxCustomMsgDefinition() {
  static const std::string* const kDefinition = new std::string(BuildLivoxCustomMsgDefinition());
  return *kDefinition;
}

const std::string& LivoxCustomPointDefinition() {
  static const std::string* const kDefinition = new std::string(kCustomPointText);
  return *kDefinition;
}

}  // namespace swarmlio::io::internal
