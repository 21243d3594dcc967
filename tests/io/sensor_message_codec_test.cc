// Single serialized messages (the ROS node's input, sensor_message_codec.h):
// an IMU sample and a scan (Livox CustomMsg and PointCloud2) survive
// serialize -> decode exactly; the bag reader's checks apply (non-finite
// values, stamps going back, empty scans); bad bytes are an error; the
// datatype names map to the LiDAR types and MD5 sums.
#include "swarmlio/io/sensor_message_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace swarmlio::io {
namespace {

ImuSample MakeImu(int64_t stamp_ns) {
  ImuSample imu;
  imu.stamp_ns = stamp_ns;
  imu.angular_velocity_rad_s = {0.1, -0.2, 0.3};
  imu.linear_acceleration = {0.5, 0.25, 9.81};
  return imu;
}

LidarScan MakeScan(int64_t stamp_ns, int points) {
  LidarScan scan;
  scan.stamp_ns = stamp_ns;
  for (int i = 0; i < points; ++i) {
    LidarPoint p;
    p.x = 1.0f + 0.5f * static_cast<float>(i);
    p.y = -2.0f;
    p.z = 0.25f * static_cast<float>(i);
    p.reflectivity = static_cast<float>(10 * i);
    p.offset_time_s = 1e-3 * i;
    p.line = static_cast<uint8_t>(i % 4);
    scan.points.push_back(p);
  }
  return scan;
}

TEST(SensorMessageCodec, ImuRoundTripAndChecks) {
  BagReaderOptions options;
  SensorMessageDecoder decoder(options, 0.1);
  std::vector<uint8_t> bytes;
  RosMessageType type;
  ASSERT_TRUE(SerializeImu(MakeImu(2'000'000'123), 0, &bytes, &type).ok());
  EXPECT_EQ(type.datatype, "sensor_msgs/Imu");
  EXPECT_EQ(type.md5sum, ExpectedMd5("sensor_msgs/Imu"));
  EXPECT_FALSE(type.definition.empty());
  ImuSample imu;
  bool accepted = false;
  ASSERT_TRUE(decoder.DecodeImu(bytes.data(), bytes.size(), &imu, &accepted).ok());
  ASSERT_TRUE(accepted);
  EXPECT_EQ(imu.stamp_ns, 2'000'000'123);
  EXPECT_EQ(imu.angular_velocity_rad_s, MakeImu(0).angular_velocity_rad_s);
  EXPECT_EQ(imu.linear_acceleration, MakeImu(0).linear_acceleration);
  // A stamp before the previous one: skipped and counted.
  ASSERT_TRUE(SerializeImu(MakeImu(1'999'000'000), 1, &bytes, &type).ok());
  ASSERT_TRUE(decoder.DecodeImu(bytes.data(), bytes.size(), &imu, &accepted).ok());
  EXPECT_FALSE(accepted);
  EXPECT_EQ(decoder.stats().Skipped(SkipReason::kImuNonMonotonic), 1);
  // Non-finite: skipped and counted.
  ImuSample nan = MakeImu(2'100'000'000);
  nan.linear_acceleration.x() = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(SerializeImu(nan, 2, &bytes, &type).ok());
  ASSERT_TRUE(decoder.DecodeImu(bytes.data(), bytes.size(), &imu, &accepted).ok());
  EXPECT_FALSE(accepted);
  EXPECT_EQ(decoder.stats().Skipped(SkipReason::kImuNonFinite), 1);
  EXPECT_EQ(decoder.stats().imu_samples, 1);
  // Cut bytes: an error.
  bytes.resize(bytes.size() / 2);
  EXPECT_FALSE(decoder.DecodeImu(bytes.data(), bytes.size(), &imu, &accepted).ok());
}

TEST(SensorMessageCodec, ScansRoundTripAsCustomMsgAndPointCloud2) {
  for (const LidarMessageFormat format :
       {LidarMessageFormat::kLivoxCustomMsg, LidarMessageFormat::kPointCloud2}) {
    SCOPED_TRACE(static_cast<int>(format));
    BagWriterOptions writer;
    writer.lidar_format = format;
    BagReaderOptions options;
    options.point_time_unit = writer.point_time_unit;
    SensorMessageDecoder decoder(options, 0.1);
    const LidarScan sent = MakeScan(3'000'000'000, 20);
    std::vector<uint8_t> bytes;
    RosMessageType type;
    ASSERT_TRUE(SerializeScan(sent, writer, 7, &bytes, &type).ok());
    LidarMessageType lidar_type;
    ASSERT_TRUE(LidarMessageTypeFromDatatype(type.datatype, &lidar_type));
    EXPECT_EQ(lidar_type == LidarMessageType::kLivoxCustomMsg,
              format == LidarMessageFormat::kLivoxCustomMsg);
    EXPECT_EQ(type.md5sum, ExpectedMd5(type.datatype));
    LidarScan scan;
    bool accepted = false;
    const Status s = decoder.DecodeScan(lidar_type, bytes.data(), bytes.size(), &scan, &accepted);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_TRUE(accepted);
    EXPECT_EQ(scan.stamp_ns, sent.stamp_ns);
    ASSERT_EQ(scan.points.size(), sent.points.size());
    for (size_t i = 0; i < sent.points.size(); ++i) {
      EXPECT_EQ(scan.points[i].x, sent.points[i].x);
      EXPECT_EQ(scan.points[i].y, sent.points[i].y);
      EXPECT_EQ(scan.points[i].z, sent.points[i].z);
      EXPECT_NEAR(scan.points[i].offset_time_s, sent.points[i].offset_time_s, 1e-12);
    }
    // An empty scan and a scan going back are skipped.
    ASSERT_TRUE(SerializeScan(MakeScan(3'100'000'000, 0), writer, 8, &bytes, &type).ok());
    ASSERT_TRUE(decoder.DecodeScan(lidar_type, bytes.data(), bytes.size(), &scan, &accepted).ok());
    EXPECT_FALSE(accepted);
    ASSERT_TRUE(SerializeScan(MakeScan(2'900'000'000, 5), writer, 9, &bytes, &type).ok());
    ASSERT_TRUE(decoder.DecodeScan(lidar_type, bytes.data(), bytes.size(), &scan, &accepted).ok());
    EXPECT_FALSE(accepted);
    EXPECT_EQ(decoder.stats().Skipped(SkipReason::kScanEmpty), 1);
    EXPECT_EQ(decoder.stats().Skipped(SkipReason::kScanNonMonotonic), 1);
    EXPECT_EQ(decoder.stats().scans, 1);
  }
}

TEST(SensorMessageCodec, DatatypeNames) {
  LidarMessageType type;
  EXPECT_TRUE(LidarMessageTypeFromDatatype("livox_ros_driver2/CustomMsg", &type));
  EXPECT_EQ(type, LidarMessageType::kLivoxCustomMsg);
  EXPECT_TRUE(LidarMessageTypeFromDatatype("sensor_msgs/PointCloud2", &type));
  EXPECT_EQ(type, LidarMessageType::kPointCloud2);
  EXPECT_FALSE(LidarMessageTypeFromDatatype("sensor_msgs/LaserScan", &type));
  EXPECT_EQ(ExpectedMd5("livox_ros_driver/CustomMsg"), ExpectedMd5("livox_ros_driver2/CustomMsg"));
  EXPECT_EQ(ExpectedMd5("std_msgs/String"), "");
}

}  // namespace
}  // namespace swarmlio::io
