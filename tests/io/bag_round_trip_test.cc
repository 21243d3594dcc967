// Write records with BagWriter, read them back with BagReader, compare bit
// for bit; and check what other ROS tools see (connection type and MD5).
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

using testing::MakeImu;
using testing::MakeLivoxScan;
using testing::MakePose;
using testing::MakeScan;
using testing::ReadAll;
using testing::Select;
using testing::TempDir;

TEST(BagRoundTripTest, ImuPoseAndCustomMsgBitExact) {
  TempDir dir;
  const std::string path = dir.File("all.bag");
  std::vector<ImuSample> imus;
  std::vector<LidarScan> scans;
  std::vector<PoseStamped> poses;
  {
    std::unique_ptr<BagWriter> writer;
    ASSERT_TRUE(BagWriter::Open(path, BagWriterOptions(), &writer).ok());
    for (int i = 0; i < 30; ++i) {
      imus.push_back(MakeImu(i, 1000000000LL * 3 + i * 4999999LL + 1));
      ASSERT_TRUE(writer->WriteImu(imus.back()).ok());
    }
    for (int i = 0; i < 4; ++i) {
      scans.push_back(MakeLivoxScan(i, 3000000000LL + i * 33333333LL, 60 + i));
      ASSERT_TRUE(writer->WriteScan(scans.back()).ok());
      poses.push_back(MakePose(i, 3000000000LL + i * 33333333LL + 7));
      ASSERT_TRUE(writer->WriteGroundTruth(poses.back()).ok());
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  std::vector<BagRecord> records;
  ReadStats stats;
  const Status status = ReadAll(path, BagReaderOptions(), &records, &stats);
  ASSERT_TRUE(status.ok()) << status.message();
  const auto imus_read = Select<ImuSample>(records);
  const auto scans_read = Select<LidarScan>(records);
  const auto poses_read = Select<PoseStamped>(records);
  ASSERT_EQ(imus_read.size(), imus.size());
  ASSERT_EQ(scans_read.size(), scans.size());
  ASSERT_EQ(poses_read.size(), poses.size());
  for (size_t i = 0; i < imus.size(); ++i) testing::ExpectImuEqual(imus[i], imus_read[i]);
  for (size_t i = 0; i < scans.size(); ++i) testing::ExpectScanEqual(scans[i], scans_read[i]);
  for (size_t i = 0; i < poses.size(); ++i) testing::ExpectPoseEqual(poses[i], poses_read[i]);
  EXPECT_EQ(stats.imu_samples, 30);
  EXPECT_EQ(stats.scans, 4);
  EXPECT_EQ(stats.ground_truth_poses, 4);
  EXPECT_EQ(stats.points, 60 + 61 + 62 + 63);
  EXPECT_EQ(stats.TotalSkipped(), 0);
}

class BagPointCloud2UnitTest : public ::testing::TestWithParam<TimestampUnit> {};

TEST_P(BagPointCloud2UnitTest, PointCloud2BitExact) {
  TempDir dir;
  const std::string path = dir.File("cloud.bag");
  BagWriterOptions write_options;
  write_options.lidar_format = LidarMessageFormat::kPointCloud2;
  write_options.point_time_unit = GetParam();
  write_options.point_time_field = "offset_t";
  write_options.lidar_topic = "/points";
  std::vector<LidarScan> scans;
  {
    std::unique_ptr<BagWriter> writer;
    ASSERT_TRUE(BagWriter::Open(path, write_options, &writer).ok());
    ASSERT_TRUE(writer->WriteImu(MakeImu(0, 10)).ok());
    for (int i = 0; i < 3; ++i) {
      scans.push_back(MakeScan(i, 1000000000LL + i * 100000000LL, 200));
      ASSERT_TRUE(writer->WriteScan(scans.back()).ok());
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  BagReaderOptions read_options;
  read_options.lidar_topic = "/points";
  read_options.point_time_unit = GetParam();
  read_options.point_time_field = "offset_t";
  std::vector<BagRecord> records;
  ASSERT_TRUE(ReadAll(path, read_options, &records).ok());
  const auto scans_read = Select<LidarScan>(records);
  ASSERT_EQ(scans_read.size(), scans.size());
  for (size_t i = 0; i < scans.size(); ++i) testing::ExpectScanEqual(scans[i], scans_read[i]);

  std::unique_ptr<BagReader> reader;
  ASSERT_TRUE(BagReader::Open(path, read_options, &reader).ok());
  EXPECT_EQ(reader->lidar_message_type(), LidarMessageType::kPointCloud2);
  EXPECT_FALSE(reader->has_ground_truth());
}

INSTANTIATE_TEST_SUITE_P(AllUnits,
                         BagPointCloud2UnitTest,
                         ::testing::Values(TimestampUnit::kSecond,
                                           TimestampUnit::kMillisecond,
                                           TimestampUnit::kMicrosecond,
                                           TimestampUnit::kNanosecond),
                         [](const ::testing::TestParamInfo<TimestampUnit>& param_info) {
                           return std::string(config::EnumToString(param_info.param));
                         });

TEST(BagRoundTripTest, CustomMsgConnectionHasDriverTypeMd5AndDefinition) {
  TempDir dir;
  const std::string path = dir.File("livox.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 40);
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  bool found = false;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    if (c->topic != "/livox/lidar") continue;
    found = true;
    EXPECT_EQ(c->datatype, "livox_ros_driver/CustomMsg");
    EXPECT_EQ(c->md5sum, "e4d6829bdfe657cb6c21a746c86b21a6");
    EXPECT_NE(c->msg_def.find("MSG: livox_ros_driver/CustomPoint"), std::string::npos);
    EXPECT_EQ((*c->header)["md5sum"], "e4d6829bdfe657cb6c21a746c86b21a6");
    EXPECT_EQ((*c->header)["type"], "livox_ros_driver/CustomMsg");
  }
  EXPECT_TRUE(found);
  bag.close();
}

TEST(BagRoundTripTest, DebianClassesReadWhatWeWrite) {
  TempDir dir;
  const std::string path = dir.File("debian.bag");
  BagWriterOptions options;
  options.lidar_format = LidarMessageFormat::kPointCloud2;
  testing::WriteSimpleBag(path, options, 21);
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  int imu = 0, clouds = 0, poses = 0;
  for (const rosbag::MessageInstance& m : view) {
    if (auto msg = m.instantiate<sensor_msgs::Imu>()) {
      EXPECT_EQ(msg->header.frame_id, "imu_link");
      ++imu;
    } else if (auto cloud = m.instantiate<sensor_msgs::PointCloud2>()) {
      EXPECT_EQ(cloud->width, 20u);
      ++clouds;
    } else if (auto pose = m.instantiate<geometry_msgs::PoseStamped>()) {
      EXPECT_EQ(pose->header.frame_id, "world");
      ++poses;
    }
  }
  EXPECT_EQ(imu, 21);
  EXPECT_EQ(clouds, 2);
  EXPECT_EQ(poses, 3);
  bag.close();
}

TEST(BagRoundTripTest, RecordsComeOutInStampOrderAcrossTopics) {
  TempDir dir;
  const std::string path = dir.File("order.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 200);
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(path, BagReaderOptions(), &records, &stats).ok());
  ASSERT_EQ(records.size(), 200u + 10u + 20u);
  for (size_t i = 1; i < records.size(); ++i) {
    ASSERT_LE(records[i - 1].stamp_ns(), records[i].stamp_ns()) << i;
    if (records[i - 1].stamp_ns() == records[i].stamp_ns()) {
      // Ties: IMU before scan before pose.
      EXPECT_LE(records[i - 1].data.index(), records[i].data.index()) << i;
    }
  }
  EXPECT_EQ(stats.imu_samples, 200);
  EXPECT_EQ(stats.scans, 10);
  EXPECT_EQ(stats.ground_truth_poses, 20);
}

TEST(BagRoundTripTest, CompressedBagsReadBack) {
  for (BagCompression compression : {BagCompression::kLz4, BagCompression::kBz2}) {
    TempDir dir;
    const std::string path = dir.File("compressed.bag");
    BagWriterOptions options;
    options.compression = compression;
    testing::WriteSimpleBag(path, options, 100);
    std::vector<BagRecord> records;
    const Status status = ReadAll(path, BagReaderOptions(), &records);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(records.size(), 100u + 5u + 10u);
  }
}

TEST(BagRoundTripTest, WriterRejectsBadInputAndWritesAfterClose) {
  TempDir dir;
  std::unique_ptr<BagWriter> writer;
  BagWriterOptions bad;
  bad.imu_topic = bad.lidar_topic;
  EXPECT_EQ(BagWriter::Open(dir.File("x.bag"), bad, &writer).code(),
            Status::Code::kInvalidArgument);
  EXPECT_FALSE(BagWriter::Open(dir.File("no_dir/x.bag"), BagWriterOptions(), &writer).ok());
  ASSERT_TRUE(BagWriter::Open(dir.File("x.bag"), BagWriterOptions(), &writer).ok());
  EXPECT_EQ(writer->WriteImu(MakeImu(0, -5)).code(), Status::Code::kOutOfRange);
  EXPECT_TRUE(writer->WriteImu(MakeImu(0, 0)).ok()) << "stamp 0 is stored at bag time 1 ns";
  ASSERT_TRUE(writer->Close().ok());
  EXPECT_EQ(writer->WriteImu(MakeImu(0, 5)).code(), Status::Code::kFailedPrecondition);
  EXPECT_TRUE(writer->Close().ok());
}

}  // namespace
}  // namespace swarmlio::io
