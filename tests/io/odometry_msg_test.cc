// nav_msgs/Odometry: our traits and genmsg definition (MD5 recomputed from
// the text), and the bounds-checked decoder of its pose part.
#include "src/io/odometry_msg.h"

#include <geometry_msgs/PoseWithCovariance.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "src/io/pose_codec.h"
#include "tests/io/genmsg_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io::internal {
namespace {

using testing::BitEqual;
using testing::Serialize;

TEST(OdometryMsgTest, TraitsAndDefinitionMatchNavMsgs) {
  EXPECT_STREQ(ros::message_traits::MD5Sum<NavOdometry>::value(),
               "cd5e73d190d741a2f92e81eda573aca7");
  EXPECT_STREQ(ros::message_traits::DataType<NavOdometry>::value(), "nav_msgs/Odometry");
  static_assert(ros::message_traits::HasHeader<NavOdometry>::value);
  const std::string definition = ros::message_traits::Definition<NavOdometry>::value();
  EXPECT_EQ(definition.rfind("# This represents an estimate of a position and velocity in free "
                             "space.  \n",
                             0),
            0u);
  EXPECT_EQ(definition.back(), '\n');
  EXPECT_NE(definition[definition.size() - 2], '\n');

  const auto sections = testing::SplitDefinition("nav_msgs/Odometry", definition);
  const std::vector<std::string> expected_order = {
      "MSG: std_msgs/Header",          "MSG: geometry_msgs/PoseWithCovariance",
      "MSG: geometry_msgs/Pose",       "MSG: geometry_msgs/Point",
      "MSG: geometry_msgs/Quaternion", "MSG: geometry_msgs/TwistWithCovariance",
      "MSG: geometry_msgs/Twist",      "MSG: geometry_msgs/Vector3"};
  size_t previous = 0;
  for (const std::string& section : expected_order) {
    const size_t at = definition.find("\n" + section + "\n");
    ASSERT_NE(at, std::string::npos) << section;
    EXPECT_GT(at, previous) << section;  // genmsg's depth-first order
    previous = at;
  }
  ASSERT_EQ(sections.size(), 9u);
  EXPECT_EQ(testing::GenmsgMd5("geometry_msgs/PoseWithCovariance", sections),
            ros::message_traits::MD5Sum<geometry_msgs::PoseWithCovariance>::value());
  EXPECT_EQ(testing::GenmsgMd5("nav_msgs/Odometry", sections), kNavOdometryMd5);
}

PoseStamped SamplePose() {
  PoseStamped pose;
  pose.stamp_ns = 1700000000123456789LL;
  pose.frame_id = "map";
  pose.p_b_in_G = Eigen::Vector3d(1.25, -3.0 / 7.0, 1e-9);
  pose.q_G_b.coeffs() << 0.1, -0.2, 0.3, 0.9;  // not normalized: kept as stored
  return pose;
}

TEST(OdometryMsgTest, PoseRoundTripsBitExactAndTheRestIsSkipped) {
  const PoseStamped pose = SamplePose();
  NavOdometry msg;
  ASSERT_TRUE(EncodeOdometry(pose, 7, &msg).ok());
  msg.child_frame_id = "a_longer_child_frame";
  msg.pose.covariance[35] = 4.0;
  msg.twist.twist.linear.x = 3.0;
  msg.twist.covariance[0] = 9.0;
  const std::vector<uint8_t> bytes = Serialize(msg);
  EXPECT_EQ(bytes.size(), 4u + 8u + 4u + 3u + 4u + 20u + 7u * 8u + 36u * 8u + 6u * 8u + 36u * 8u);
  PoseStamped read;
  const Status status = DecodeOdometryPose(bytes.data(), bytes.size(), &read);
  ASSERT_TRUE(status.ok()) << status.message();
  testing::ExpectPoseEqual(read, pose);
}

TEST(OdometryMsgTest, TruncatedOrLongerBytesAreDataLoss) {
  NavOdometry msg;
  ASSERT_TRUE(EncodeOdometry(SamplePose(), 0, &msg).ok());
  std::vector<uint8_t> bytes = Serialize(msg);
  PoseStamped read;
  for (size_t size : {size_t{0}, size_t{10}, size_t{40}, bytes.size() - 1}) {
    const Status status = DecodeOdometryPose(bytes.data(), size, &read);
    EXPECT_EQ(status.code(), Status::Code::kDataLoss) << size;
  }
  const Status cut = DecodeOdometryPose(bytes.data(), bytes.size() - 8, &read);
  EXPECT_NE(cut.message().find("twist.covariance"), std::string::npos) << cut.message();
  bytes.push_back(0);
  const Status longer = DecodeOdometryPose(bytes.data(), bytes.size(), &read);
  EXPECT_EQ(longer.code(), Status::Code::kDataLoss);
  EXPECT_NE(longer.message().find("nav_msgs/Odometry"), std::string::npos) << longer.message();
  // A child_frame_id length beyond the message.
  std::vector<uint8_t> lying = Serialize(msg);
  const size_t child_length_at = 4 + 8 + 4 + 3;  // seq, stamp, frame_id "map"
  lying[child_length_at + 3] = 0x7f;
  EXPECT_EQ(DecodeOdometryPose(lying.data(), lying.size(), &read).code(), Status::Code::kDataLoss);
}

}  // namespace
}  // namespace swarmlio::io::internal
