// livox_ros_driver/CustomMsg: traits, the genmsg definition text and its MD5,
// the 19-byte point layout, and the bounds-checked decoder.
#include "src/io/custom_msg.h"

#include <gtest/gtest.h>

#include <boost/uuid/detail/md5.hpp>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "src/io/custom_msg_codec.h"
#include "tests/io/genmsg_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io::internal {
namespace {

using testing::GenmsgMd5;
using testing::Serialize;
using testing::SplitDefinition;

TEST(CustomMsgTest, TraitsMatchTheLivoxDriver) {
  EXPECT_STREQ(ros::message_traits::MD5Sum<LivoxCustomMsg>::value(),
               "e4d6829bdfe657cb6c21a746c86b21a6");
  EXPECT_STREQ(ros::message_traits::DataType<LivoxCustomMsg>::value(),
               "livox_ros_driver/CustomMsg");
  static_assert(ros::message_traits::HasHeader<LivoxCustomMsg>::value);
  static_assert(ros::message_traits::IsMessage<LivoxCustomMsg>::value);
  const LivoxCustomMsg msg;
  EXPECT_STREQ(ros::message_traits::md5sum(msg), kLivoxCustomMsgMd5);
  EXPECT_STREQ(ros::message_traits::datatype(msg), kLivoxCustomMsgDataType);
}

TEST(CustomMsgTest, DefinitionHasGenmsgLayoutAndItsMd5IsTheDriverMd5) {
  const std::string definition = ros::message_traits::Definition<LivoxCustomMsg>::value();
  const std::string separator(80, '=');
  // Message text, blank line, separator, "MSG: type", text; no final blank line.
  EXPECT_NE(definition.find("\n\n" + separator + "\nMSG: std_msgs/Header\n"), std::string::npos);
  EXPECT_NE(definition.find("\n\n" + separator + "\nMSG: livox_ros_driver/CustomPoint\n"),
            std::string::npos);
  EXPECT_LT(definition.find("MSG: std_msgs/Header"),
            definition.find("MSG: livox_ros_driver/CustomPoint"));
  EXPECT_EQ(definition.back(), '\n');
  EXPECT_NE(definition[definition.size() - 2], '\n');
  EXPECT_EQ(definition.find("uint32 offset_time"),
            definition.rfind("uint32 offset_time"));  // CustomPoint appears once

  const auto sections = SplitDefinition("livox_ros_driver/CustomMsg", definition);
  ASSERT_EQ(sections.size(), 3u);
  EXPECT_EQ(sections.at("std_msgs/Header"),
            std::string(ros::message_traits::Definition<std_msgs::Header>::value()));
  EXPECT_EQ(GenmsgMd5("std_msgs/Header", sections),
            ros::message_traits::MD5Sum<std_msgs::Header>::value());
  EXPECT_EQ(GenmsgMd5("livox_ros_driver/CustomPoint", sections), kLivoxCustomPointMd5);
  EXPECT_EQ(GenmsgMd5("livox_ros_driver/CustomMsg", sections), "e4d6829bdfe657cb6c21a746c86b21a6");
}

TEST(CustomMsgTest, PointsAre19BytesWithTheDriverLayout) {
  LivoxCustomMsg msg;
  msg.header.frame_id = "ab";
  msg.timebase = 0x1122334455667788ull;
  msg.point_num = 2;
  msg.lidar_id = 7;
  msg.rsvd = {1, 2, 3};
  msg.points.resize(2);
  msg.points[1].offset_time = 0xA1B2C3D4u;
  msg.points[1].x = 1.5f;
  msg.points[1].y = -2.0f;
  msg.points[1].z = 0.25f;
  msg.points[1].reflectivity = 200;
  msg.points[1].tag = 0x30;
  msg.points[1].line = 5;
  const std::vector<uint8_t> bytes = Serialize(msg);
  const size_t header_bytes = 4 + 8 + 4 + 2;
  const size_t points_start = header_bytes + 8 + 4 + 1 + 3 + 4;
  ASSERT_EQ(bytes.size(), points_start + 2 * 19);
  EXPECT_EQ(bytes[header_bytes + 12], 7);  // lidar_id after timebase and point_num
  EXPECT_EQ(bytes[points_start - 4], 2);   // points length
  const uint8_t* p = bytes.data() + points_start + 19;
  uint32_t offset_time;
  float x, y, z;
  std::memcpy(&offset_time, p + 0, 4);
  std::memcpy(&x, p + 4, 4);
  std::memcpy(&y, p + 8, 4);
  std::memcpy(&z, p + 12, 4);
  EXPECT_EQ(offset_time, 0xA1B2C3D4u);
  EXPECT_EQ(x, 1.5f);
  EXPECT_EQ(y, -2.0f);
  EXPECT_EQ(z, 0.25f);
  EXPECT_EQ(p[16], 200);
  EXPECT_EQ(p[17], 0x30);
  EXPECT_EQ(p[18], 5);
  EXPECT_EQ(ros::serialization::serializationLength(msg), bytes.size());
}

TEST(CustomMsgTest, EncodeDecodeRoundTripMatchesSerializerRead) {
  const LidarScan in = testing::MakeLivoxScan(4, 1600000000123456789LL, 100);
  LivoxCustomMsg msg;
  ASSERT_TRUE(EncodeLivoxCustomMsg(in, 3, &msg).ok());
  const std::vector<uint8_t> bytes = Serialize(msg);
  LidarScan out;
  ASSERT_TRUE(DecodeLivoxCustomMsg(bytes.data(), bytes.size(), &out).ok());
  testing::ExpectScanEqual(in, out);

  const LivoxCustomMsg back = testing::Deserialize<LivoxCustomMsg>(bytes);
  EXPECT_EQ(back.timebase, in.livox_timebase_ns);
  ASSERT_EQ(back.points.size(), out.points.size());
  for (size_t k = 0; k < back.points.size(); ++k) {
    EXPECT_EQ(static_cast<double>(back.points[k].offset_time) / 1e9, out.points[k].offset_time_s);
    EXPECT_EQ(back.points[k].x, out.points[k].x);
    EXPECT_EQ(back.points[k].line, out.points[k].line);
  }
}

TEST(CustomMsgTest, LyingLengthsAndTruncationAreDecodeErrors) {
  LivoxCustomMsg msg;
  ASSERT_TRUE(EncodeLivoxCustomMsg(testing::MakeLivoxScan(1, 1000, 5), 0, &msg).ok());
  std::vector<uint8_t> bytes = Serialize(msg);
  LidarScan scan;

  // point_num says 6, the array holds 5.
  msg.point_num = 6;
  std::vector<uint8_t> lying_num = Serialize(msg);
  Status status = DecodeLivoxCustomMsg(lying_num.data(), lying_num.size(), &scan);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_NE(status.message().find("point_num"), std::string::npos);

  // The array length claims 2^31 points.
  const size_t length_at = bytes.size() - 5 * 19 - 4;
  std::vector<uint8_t> lying_len = bytes;
  lying_len[length_at + 3] = 0x80;
  status = DecodeLivoxCustomMsg(lying_len.data(), lying_len.size(), &scan);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);

  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(DecodeLivoxCustomMsg(bytes.data(), n, &scan).ok()) << n;
  }
}

TEST(CustomMsgTest, EncodeRejectsOffsetsThatDoNotFitUint32Ns) {
  LidarScan scan = testing::MakeLivoxScan(0, 0, 3);
  LivoxCustomMsg msg;
  scan.points[1].offset_time_s = -1e-6;
  EXPECT_EQ(EncodeLivoxCustomMsg(scan, 0, &msg).code(), Status::Code::kInvalidArgument);
  scan.points[1].offset_time_s = 5.0;
  EXPECT_FALSE(EncodeLivoxCustomMsg(scan, 0, &msg).ok());
  scan.points[1].offset_time_s = std::nan("");
  EXPECT_FALSE(EncodeLivoxCustomMsg(scan, 0, &msg).ok());
}

}  // namespace
}  // namespace swarmlio::io::internal
