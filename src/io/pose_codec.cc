#include "src/io/pose_codec.h"

#include "src/io/header_codec.h"
#include "src/io/ros_time.h"
#include "src/io/wire_reader.h"

namespace swarmlio::io::internal {

Status DecodePoseStamped(const uint8_t* data, size_t size, PoseStamped* pose) {
  WireReader reader(data, size);
  SWARMLIO_RETURN_IF_ERROR(ReadRosHeader(&reader, &pose->stamp_ns, &pose->frame_id));
  for (int i = 0; i < 3; ++i) {
    SWARMLIO_RETURN_IF_ERROR(reader.ReadF64("pose.position", &pose->p_b_in_G[i]));
  }
  // geometry_msgs/Quaternion is x, y, z, w, as Eigen's coeffs().
  for (int i = 0; i < 4; ++i) {
    SWARMLIO_RETURN_IF_ERROR(reader.ReadF64("pose.orientation", &pose->q_G_b.coeffs()[i]));
  }
  return reader.ExpectEnd("geometry_msgs/PoseStamped");
}

Status EncodePoseStamped(const PoseStamped& pose, uint32_t seq, geometry_msgs::PoseStamped* msg) {
  *msg = geometry_msgs::PoseStamped();
  msg->header.seq = seq;
  SWARMLIO_RETURN_IF_ERROR(RosTimeFromStampNs(pose.stamp_ns, &msg->header.stamp));
  msg->header.frame_id = pose.frame_id;
  msg->pose.position.x = pose.p_b_in_G.x();
  msg->pose.position.y = pose.p_b_in_G.y();
  msg->pose.position.z = pose.p_b_in_G.z();
  msg->pose.orientation.x = pose.q_G_b.x();
  msg->pose.orientation.y = pose.q_G_b.y();
  msg->pose.orientation.z = pose.q_G_b.z();
  msg->pose.orientation.w = pose.q_G_b.w();
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
