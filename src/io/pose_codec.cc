#include "src/io/pose_codec.h"

#include <string>

#include "src/io/header_codec.h"
#include "src/io/ros_message_reader.h"
#include "src/io/ros_time.h"

namespace swarmlio::io::internal {
namespace {

// float64[36] covariance of PoseWithCovariance / TwistWithCovariance.
constexpr size_t kCovarianceValues = 36;
// Twist: linear and angular float64 x y z.
constexpr size_t kTwistValues = 6;

// geometry_msgs/Pose: position x y z, orientation x y z w.
Status ReadPose(RosMessageReader* reader,
                const char* position,
                const char* orientation,
                PoseStamped* pose) {
  for (int i = 0; i < 3; ++i) {
    SWARMLIO_RETURN_IF_ERROR(reader->ReadF64(position, &pose->p_b_in_G[i]));
  }
  // geometry_msgs/Quaternion is x, y, z, w, as Eigen's coeffs().
  for (int i = 0; i < 4; ++i) {
    SWARMLIO_RETURN_IF_ERROR(reader->ReadF64(orientation, &pose->q_G_b.coeffs()[i]));
  }
  return Status::Ok();
}

}  // namespace

Status DecodePoseStamped(const uint8_t* data,
                         size_t size,
                         PoseStamped* pose,
                         WireEncoding encoding) {
  RosMessageReader reader(data, size);
  SWARMLIO_RETURN_IF_ERROR(reader.Begin(encoding));
  SWARMLIO_RETURN_IF_ERROR(ReadRosHeader(&reader, &pose->stamp_ns, &pose->frame_id));
  SWARMLIO_RETURN_IF_ERROR(ReadPose(&reader, "pose.position", "pose.orientation", pose));
  return reader.ExpectEnd("geometry_msgs/PoseStamped");
}

Status DecodeOdometryPose(const uint8_t* data,
                          size_t size,
                          PoseStamped* pose,
                          WireEncoding encoding) {
  RosMessageReader reader(data, size);
  SWARMLIO_RETURN_IF_ERROR(reader.Begin(encoding));
  SWARMLIO_RETURN_IF_ERROR(ReadRosHeader(&reader, &pose->stamp_ns, &pose->frame_id));
  std::string child_frame_id;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadString("child_frame_id", &child_frame_id));
  SWARMLIO_RETURN_IF_ERROR(ReadPose(&reader, "pose.pose.position", "pose.pose.orientation", pose));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("pose.covariance", kCovarianceValues));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("twist.twist", kTwistValues));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("twist.covariance", kCovarianceValues));
  return reader.ExpectEnd(kNavOdometryDataType);
}

Status EncodeOdometry(const PoseStamped& pose, uint32_t seq, NavOdometry* msg) {
  *msg = NavOdometry();
  msg->header.seq = seq;
  SWARMLIO_RETURN_IF_ERROR(RosTimeFromStampNs(pose.stamp_ns, &msg->header.stamp));
  msg->header.frame_id = pose.frame_id;
  msg->child_frame_id = "body";
  geometry_msgs::Pose& p = msg->pose.pose;
  p.position.x = pose.p_b_in_G.x();
  p.position.y = pose.p_b_in_G.y();
  p.position.z = pose.p_b_in_G.z();
  p.orientation.x = pose.q_G_b.x();
  p.orientation.y = pose.q_G_b.y();
  p.orientation.z = pose.q_G_b.z();
  p.orientation.w = pose.q_G_b.w();
  return Status::Ok();
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
