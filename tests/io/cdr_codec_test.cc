// ROS 2 CDR decoding: each message type decodes to the same record as its
// ROS1 serialization; hand-built bytes pin the alignment rules (independent
// of our serializer); truncated or wrongly encapsulated bytes are DataLoss.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "src/io/cdr_serialize.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/pointcloud2_codec.h"
#include "src/io/pose_codec.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io::internal {
namespace {

using testing::ExpectImuEqual;
using testing::ExpectPoseEqual;
using testing::ExpectScanEqual;
using testing::MakeImu;
using testing::MakeLivoxScan;
using testing::MakePose;
using testing::MakeScan;
using testing::Serialize;

constexpr int64_t kStamp = 1700000000123456789LL;

// Appends little-endian bytes of `value` (test-side builder, no alignment).
template <class T>
void Append(std::vector<uint8_t>* out, T value) {
  uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->insert(out->end(), bytes, bytes + sizeof(T));
}

void Pad(std::vector<uint8_t>* out, size_t alignment) {
  while ((out->size() - 4) % alignment != 0) out->push_back(0xAB);  // any padding value
}

// Every prefix of `bytes` must fail to decode, without crashing.
template <class Decode>
void ExpectPrefixesFail(const std::vector<uint8_t>& bytes, Decode decode) {
  // The last 3 bytes may be final padding; shorter prefixes cut a field.
  for (size_t size = 0; size + 4 <= bytes.size(); ++size) {
    std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(size));
    EXPECT_EQ(decode(cut).code(), Status::Code::kDataLoss) << size << " of " << bytes.size();
  }
}

TEST(CdrCodecTest, ImuDecodesLikeRos1) {
  for (const std::string frame : {"", "a", "imu", "imu_link"}) {  // every alignment of what follows
    ImuSample in = MakeImu(7, kStamp);
    in.frame_id = frame;
    sensor_msgs::Imu msg;
    ASSERT_TRUE(EncodeImu(in, 3, &msg).ok());
    std::vector<uint8_t> cdr;
    SerializeCdr(msg, &cdr);
    ImuSample from_cdr, from_ros1;
    ASSERT_TRUE(DecodeImu(cdr.data(), cdr.size(), &from_cdr, WireEncoding::kCdr).ok());
    const std::vector<uint8_t> ros1 = Serialize(msg);
    ASSERT_TRUE(DecodeImu(ros1.data(), ros1.size(), &from_ros1).ok());
    ExpectImuEqual(from_cdr, in);
    ExpectImuEqual(from_cdr, from_ros1);
    ExpectPrefixesFail(cdr, [](const std::vector<uint8_t>& b) {
      ImuSample imu;
      return DecodeImu(b.data(), b.size(), &imu, WireEncoding::kCdr);
    });
  }
}

// sensor_msgs/msg/Imu built byte by byte: frame_id "ab" leaves the stream at
// 4+4+4+3 = 15 bytes after the header, so 1 padding byte precedes the
// float64 orientation.
TEST(CdrCodecTest, HandBuiltImuFollowsTheAlignmentRules) {
  std::vector<uint8_t> b = {0x00, 0x01, 0x00, 0x00};
  Append<int32_t>(&b, 12);    // sec
  Append<uint32_t>(&b, 345);  // nanosec
  Append<uint32_t>(&b, 3);    // "ab" + NUL
  b.insert(b.end(), {'a', 'b', 0});
  Pad(&b, 8);
  EXPECT_EQ(b.size(), 4u + 16u);
  const double values[] = {0, 0, 0, 1};
  for (double v : values) Append<double>(&b, v);
  for (int i = 0; i < 9; ++i) Append<double>(&b, 0.0);
  for (double v : {0.1, 0.2, 0.3}) Append<double>(&b, v);
  for (int i = 0; i < 9; ++i) Append<double>(&b, 0.0);
  for (double v : {1.5, -2.5, 9.75}) Append<double>(&b, v);
  for (int i = 0; i < 9; ++i) Append<double>(&b, 0.0);
  ImuSample imu;
  const Status status = DecodeImu(b.data(), b.size(), &imu, WireEncoding::kCdr);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(imu.stamp_ns, 12000000345LL);
  EXPECT_EQ(imu.frame_id, "ab");
  EXPECT_EQ(imu.angular_velocity_rad_s, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(imu.linear_acceleration, Eigen::Vector3d(1.5, -2.5, 9.75));
  // Up to 3 bytes of final padding are fine, 4 are not.
  b.insert(b.end(), 3, 0);
  EXPECT_TRUE(DecodeImu(b.data(), b.size(), &imu, WireEncoding::kCdr).ok());
  b.push_back(0);
  EXPECT_EQ(DecodeImu(b.data(), b.size(), &imu, WireEncoding::kCdr).code(),
            Status::Code::kDataLoss);
}

// livox_ros_driver2/msg/CustomMsg with 2 points: each point is aligned to 4,
// so 1 padding byte separates the 19-byte points.
TEST(CdrCodecTest, HandBuiltCustomMsgPointsAreAlignedToFour) {
  std::vector<uint8_t> b = {0x00, 0x01, 0x00, 0x00};
  Append<int32_t>(&b, 1);
  Append<uint32_t>(&b, 2);
  Append<uint32_t>(&b, 1);  // "" + NUL
  b.push_back(0);
  Pad(&b, 8);
  Append<uint64_t>(&b, 1000000002ULL);  // timebase
  Append<uint32_t>(&b, 2);              // point_num
  b.push_back(5);                       // lidar_id
  b.insert(b.end(), {0, 0, 0});         // rsvd
  Append<uint32_t>(&b, 2);              // points count
  for (uint32_t k = 0; k < 2; ++k) {
    Pad(&b, 4);
    Append<uint32_t>(&b, 1000 * (k + 1));
    Append<float>(&b, 1.0f + k);
    Append<float>(&b, 2.0f);
    Append<float>(&b, 3.0f);
    b.insert(b.end(), {static_cast<uint8_t>(10 + k), 0x10, static_cast<uint8_t>(k)});
  }
  LidarScan scan;
  const Status status = DecodeLivoxCustomMsg(b.data(), b.size(), &scan, WireEncoding::kCdr);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(scan.stamp_ns, 1000000002LL);
  EXPECT_EQ(scan.livox_timebase_ns, 1000000002ULL);
  EXPECT_EQ(scan.livox_lidar_id, 5);
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(scan.points[1].x, 2.0f);
  EXPECT_EQ(scan.points[1].reflectivity, 11.0f);
  EXPECT_EQ(scan.points[1].line, 1);
  EXPECT_DOUBLE_EQ(scan.points[1].offset_time_s, 2e-6);
}

TEST(CdrCodecTest, ScansDecodeLikeRos1) {
  const LidarScan livox = MakeLivoxScan(3, kStamp, 37);
  LivoxCustomMsg custom;
  ASSERT_TRUE(EncodeLivoxCustomMsg(livox, 1, &custom).ok());
  std::vector<uint8_t> cdr;
  SerializeCdr(custom, &cdr);
  LidarScan decoded;
  ASSERT_TRUE(DecodeLivoxCustomMsg(cdr.data(), cdr.size(), &decoded, WireEncoding::kCdr).ok());
  ExpectScanEqual(decoded, livox);
  ExpectPrefixesFail(cdr, [](const std::vector<uint8_t>& b) {
    LidarScan scan;
    return DecodeLivoxCustomMsg(b.data(), b.size(), &scan, WireEncoding::kCdr);
  });

  const LidarScan cloud = MakeScan(4, kStamp, 29);
  sensor_msgs::PointCloud2 pc2;
  ASSERT_TRUE(EncodePointCloud2(cloud, 2, TimestampUnit::kNanosecond, "timestamp", &pc2).ok());
  SerializeCdr(pc2, &cdr);
  PointCloud2DecodeOptions options;
  options.time_unit = TimestampUnit::kNanosecond;
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(
      DecodePointCloud2(cdr.data(), cdr.size(), options, &decoded, &info, WireEncoding::kCdr).ok());
  EXPECT_EQ(info.time_field, "timestamp");
  ExpectScanEqual(decoded, cloud);
  ExpectPrefixesFail(cdr, [&options](const std::vector<uint8_t>& b) {
    LidarScan scan;
    PointCloud2DecodeInfo unused;
    return DecodePointCloud2(b.data(), b.size(), options, &scan, &unused, WireEncoding::kCdr);
  });
}

TEST(CdrCodecTest, PosesDecodeLikeRos1) {
  const PoseStamped pose = MakePose(9, kStamp);
  geometry_msgs::PoseStamped stamped;
  ASSERT_TRUE(EncodePoseStamped(pose, 0, &stamped).ok());
  std::vector<uint8_t> cdr;
  SerializeCdr(stamped, &cdr);
  PoseStamped decoded;
  ASSERT_TRUE(DecodePoseStamped(cdr.data(), cdr.size(), &decoded, WireEncoding::kCdr).ok());
  ExpectPoseEqual(decoded, pose);
  NavOdometry odometry;
  ASSERT_TRUE(EncodeOdometry(pose, 0, &odometry).ok());
  SerializeCdr(odometry, &cdr);
  ASSERT_TRUE(DecodeOdometryPose(cdr.data(), cdr.size(), &decoded, WireEncoding::kCdr).ok());
  ExpectPoseEqual(decoded, pose);
  ExpectPrefixesFail(cdr, [](const std::vector<uint8_t>& b) {
    PoseStamped p;
    return DecodeOdometryPose(b.data(), b.size(), &p, WireEncoding::kCdr);
  });
}

TEST(CdrCodecTest, BadEncapsulationAndStringsAreDataLoss) {
  sensor_msgs::Imu msg;
  ASSERT_TRUE(EncodeImu(MakeImu(1, kStamp), 0, &msg).ok());
  std::vector<uint8_t> cdr;
  SerializeCdr(msg, &cdr);
  ImuSample imu;
  std::vector<uint8_t> big_endian = cdr;
  big_endian[1] = 0x00;  // CDR_BE
  Status status = DecodeImu(big_endian.data(), big_endian.size(), &imu, WireEncoding::kCdr);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_NE(status.message().find("encapsulation"), std::string::npos) << status.message();
  std::vector<uint8_t> no_nul = cdr;
  no_nul[4 + 8 + 4 + msg.header.frame_id.size()] = 'x';  // the frame_id's NUL
  status = DecodeImu(no_nul.data(), no_nul.size(), &imu, WireEncoding::kCdr);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_NE(status.message().find("NUL"), std::string::npos) << status.message();
  std::vector<uint8_t> negative = cdr;
  negative[7] = 0x80;  // sec < 0
  EXPECT_EQ(DecodeImu(negative.data(), negative.size(), &imu, WireEncoding::kCdr).code(),
            Status::Code::kDataLoss);
}

}  // namespace
}  // namespace swarmlio::io::internal
