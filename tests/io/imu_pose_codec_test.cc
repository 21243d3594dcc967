// Cross-checks the bounds-checked IMU and pose decoders against ROS's own
// serialization of the Debian message classes.
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <sensor_msgs/Imu.h>

#include <vector>

#include "src/io/imu_codec.h"
#include "src/io/pose_codec.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io::internal {
namespace {

using testing::Deserialize;
using testing::Serialize;

sensor_msgs::Imu MakeImuMsg() {
  sensor_msgs::Imu msg;
  msg.header.seq = 77;
  msg.header.stamp.sec = 1700000000;
  msg.header.stamp.nsec = 123456789;
  msg.header.frame_id = "imu";
  msg.orientation.x = 0.1;
  msg.orientation.y = 0.2;
  msg.orientation.z = 0.3;
  msg.orientation.w = 0.9;
  for (int i = 0; i < 9; ++i) {
    msg.orientation_covariance[i] = i;
    msg.angular_velocity_covariance[i] = 10 + i;
    msg.linear_acceleration_covariance[i] = 20 + i;
  }
  msg.angular_velocity.x = 0.5;
  msg.angular_velocity.y = -0.25;
  msg.angular_velocity.z = 1e-9;
  msg.linear_acceleration.x = 9.81;
  msg.linear_acceleration.y = -0.001;
  msg.linear_acceleration.z = 3.0;
  return msg;
}

TEST(ImuCodecTest, DecodeMatchesRosDeserialization) {
  const std::vector<uint8_t> bytes = Serialize(MakeImuMsg());
  const sensor_msgs::Imu ros_msg = Deserialize<sensor_msgs::Imu>(bytes);
  ImuSample imu;
  ASSERT_TRUE(DecodeImu(bytes.data(), bytes.size(), &imu).ok());
  EXPECT_EQ(imu.stamp_ns, 1700000000LL * 1000000000LL + 123456789LL);
  EXPECT_EQ(imu.stamp_ns, static_cast<int64_t>(ros_msg.header.stamp.toNSec()));
  EXPECT_EQ(imu.frame_id, ros_msg.header.frame_id);
  EXPECT_EQ(imu.angular_velocity_rad_s.x(), ros_msg.angular_velocity.x);
  EXPECT_EQ(imu.angular_velocity_rad_s.y(), ros_msg.angular_velocity.y);
  EXPECT_EQ(imu.angular_velocity_rad_s.z(), ros_msg.angular_velocity.z);
  EXPECT_EQ(imu.linear_acceleration.x(), ros_msg.linear_acceleration.x);
  EXPECT_EQ(imu.linear_acceleration.y(), ros_msg.linear_acceleration.y);
  EXPECT_EQ(imu.linear_acceleration.z(), ros_msg.linear_acceleration.z);
}

TEST(ImuCodecTest, EncodeDecodeRoundTrip) {
  const ImuSample in = testing::MakeImu(5, 42000000123LL);
  sensor_msgs::Imu msg;
  ASSERT_TRUE(EncodeImu(in, 9, &msg).ok());
  const std::vector<uint8_t> bytes = Serialize(msg);
  const sensor_msgs::Imu ros_msg = Deserialize<sensor_msgs::Imu>(bytes);
  EXPECT_EQ(ros_msg.header.seq, 9u);
  EXPECT_EQ(ros_msg.orientation_covariance[0], -1.0);
  EXPECT_EQ(ros_msg.orientation.w, 1.0);
  ImuSample out;
  ASSERT_TRUE(DecodeImu(bytes.data(), bytes.size(), &out).ok());
  testing::ExpectImuEqual(in, out);
}

TEST(ImuCodecTest, EveryTruncationAndTrailingByteIsAnError) {
  std::vector<uint8_t> bytes = Serialize(MakeImuMsg());
  for (size_t n = 0; n < bytes.size(); ++n) {
    ImuSample imu;
    EXPECT_EQ(DecodeImu(bytes.data(), n, &imu).code(), Status::Code::kDataLoss) << n;
  }
  bytes.push_back(0);
  ImuSample imu;
  EXPECT_FALSE(DecodeImu(bytes.data(), bytes.size(), &imu).ok());
}

TEST(ImuCodecTest, LyingFrameIdLengthIsAnError) {
  std::vector<uint8_t> bytes = Serialize(MakeImuMsg());
  // frame_id length sits after seq, sec, nsec.
  bytes[12] = 0xff;
  bytes[13] = 0xff;
  bytes[14] = 0xff;
  bytes[15] = 0x7f;
  ImuSample imu;
  EXPECT_EQ(DecodeImu(bytes.data(), bytes.size(), &imu).code(), Status::Code::kDataLoss);
}

TEST(ImuCodecTest, EncodeRejectsStampsOutsideRosTime) {
  sensor_msgs::Imu msg;
  EXPECT_FALSE(EncodeImu(testing::MakeImu(0, -1), 0, &msg).ok());
  EXPECT_FALSE(EncodeImu(testing::MakeImu(0, (int64_t{1} << 32) * 1000000000LL), 0, &msg).ok());
  EXPECT_TRUE(EncodeImu(testing::MakeImu(0, 0), 0, &msg).ok());
}

TEST(PoseCodecTest, DecodeMatchesRosDeserialization) {
  geometry_msgs::PoseStamped msg;
  msg.header.stamp.sec = 12;
  msg.header.stamp.nsec = 999999999;
  msg.header.frame_id = "map";
  msg.pose.position.x = 1.5;
  msg.pose.position.y = -2.5;
  msg.pose.position.z = 1e6;
  msg.pose.orientation.x = 0.5;
  msg.pose.orientation.y = -0.5;
  msg.pose.orientation.z = 0.5;
  msg.pose.orientation.w = 0.5;
  const std::vector<uint8_t> bytes = Serialize(msg);
  const auto ros_msg = Deserialize<geometry_msgs::PoseStamped>(bytes);
  PoseStamped pose;
  ASSERT_TRUE(DecodePoseStamped(bytes.data(), bytes.size(), &pose).ok());
  EXPECT_EQ(pose.stamp_ns, static_cast<int64_t>(ros_msg.header.stamp.toNSec()));
  EXPECT_EQ(pose.frame_id, "map");
  EXPECT_EQ(pose.p_b_in_G.x(), ros_msg.pose.position.x);
  EXPECT_EQ(pose.p_b_in_G.y(), ros_msg.pose.position.y);
  EXPECT_EQ(pose.p_b_in_G.z(), ros_msg.pose.position.z);
  EXPECT_EQ(pose.q_G_b.x(), ros_msg.pose.orientation.x);
  EXPECT_EQ(pose.q_G_b.y(), ros_msg.pose.orientation.y);
  EXPECT_EQ(pose.q_G_b.z(), ros_msg.pose.orientation.z);
  EXPECT_EQ(pose.q_G_b.w(), ros_msg.pose.orientation.w);
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(DecodePoseStamped(bytes.data(), n, &pose).ok()) << n;
  }
}

TEST(PoseCodecTest, EncodeDecodeRoundTrip) {
  const PoseStamped in = testing::MakePose(3, 5000000007LL);
  geometry_msgs::PoseStamped msg;
  ASSERT_TRUE(EncodePoseStamped(in, 1, &msg).ok());
  const std::vector<uint8_t> bytes = Serialize(msg);
  PoseStamped out;
  ASSERT_TRUE(DecodePoseStamped(bytes.data(), bytes.size(), &out).ok());
  testing::ExpectPoseEqual(in, out);
}

}  // namespace
}  // namespace swarmlio::io::internal
