#include "src/io/imu_codec.h"

#include "src/io/header_codec.h"
#include "src/io/ros_message_reader.h"
#include "src/io/ros_time.h"

namespace swarmlio::io::internal {
namespace {

Status ReadVector3(RosMessageReader* reader, const char* field, Eigen::Vector3d* v) {
  for (int i = 0; i < 3; ++i) SWARMLIO_RETURN_IF_ERROR(reader->ReadF64(field, &(*v)[i]));
  return Status::Ok();
}

}  // namespace

Status DecodeImu(const uint8_t* data, size_t size, ImuSample* imu, WireEncoding encoding) {
  RosMessageReader reader(data, size);
  SWARMLIO_RETURN_IF_ERROR(reader.Begin(encoding));
  SWARMLIO_RETURN_IF_ERROR(ReadRosHeader(&reader, &imu->stamp_ns, &imu->frame_id));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("orientation", 4));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("orientation_covariance", 9));
  SWARMLIO_RETURN_IF_ERROR(ReadVector3(&reader, "angular_velocity", &imu->angular_velocity_rad_s));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("angular_velocity_covariance", 9));
  SWARMLIO_RETURN_IF_ERROR(ReadVector3(&reader, "linear_acceleration", &imu->linear_acceleration));
  SWARMLIO_RETURN_IF_ERROR(reader.SkipF64s("linear_acceleration_covariance", 9));
  return reader.ExpectEnd("sensor_msgs/Imu");
}

Status EncodeImu(const ImuSample& imu, uint32_t seq, sensor_msgs::Imu* msg) {
  *msg = sensor_msgs::Imu();
  msg->header.seq = seq;
  SWARMLIO_RETURN_IF_ERROR(RosTimeFromStampNs(imu.stamp_ns, &msg->header.stamp));
  msg->header.frame_id = imu.frame_id;
  msg->orientation.w = 1.0;
  msg->orientation_covariance[0] = -1.0;
  msg->angular_velocity.x = imu.angular_velocity_rad_s.x();
  msg->angular_velocity.y = imu.angular_velocity_rad_s.y();
  msg->angular_velocity.z = imu.angular_velocity_rad_s.z();
  msg->linear_acceleration.x = imu.linear_acceleration.x();
  msg->linear_acceleration.y = imu.linear_acceleration.y();
  msg->linear_acceleration.z = imu.linear_acceleration.z();
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
