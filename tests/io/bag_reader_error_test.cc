// BagReader on broken input: missing, garbage and truncated files (without
// recovery; bag_recovery_test.cc recovers them), missing topics, wrong types,
// corrupt messages, NaNs, stamps going backwards and empty scans. Each is an
// error Status or a counted skip, never a crash.
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "swarmlio/io/bag_info.h"
#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

using testing::MakeImu;
using testing::MakeLivoxScan;
using testing::MakePose;
using testing::RawMessage;
using testing::ReadAll;
using testing::Select;
using testing::TempDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

ros::Time T(int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

// A valid CustomMsg's bytes, for corruption.
RawMessage CustomMsgBytes(const LidarScan& scan) {
  internal::LivoxCustomMsg msg;
  EXPECT_TRUE(internal::EncodeLivoxCustomMsg(scan, 0, &msg).ok());
  RawMessage raw;
  raw.datatype = internal::kLivoxCustomMsgDataType;
  raw.md5sum = internal::kLivoxCustomMsgMd5;
  raw.definition = internal::LivoxCustomMsgDefinition();
  raw.bytes = testing::Serialize(msg);
  return raw;
}

TEST(BagReaderErrorTest, MissingFileIsNotFound) {
  TempDir dir;
  std::unique_ptr<BagReader> reader;
  const Status status = BagReader::Open(dir.File("nope.bag"), BagReaderOptions(), &reader);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_TRUE(Contains(status.message(), dir.File("nope.bag")));
  EXPECT_EQ(reader, nullptr);
}

TEST(BagReaderErrorTest, GarbageFilesAreErrors) {
  TempDir dir;
  uint32_t state = 12345;
  auto next_byte = [&state]() {
    state = state * 1664525u + 1013904223u;
    return static_cast<char>(state >> 24);
  };
  const std::vector<std::string> prefixes = {"", "#ROSBAG V2.0\n", "#ROSBAG V1.2\n"};
  for (size_t k = 0; k < prefixes.size(); ++k) {
    for (size_t size : {0, 5, 100, 5000}) {
      const std::string path =
          dir.File("garbage" + std::to_string(k) + "_" + std::to_string(size) + ".bag");
      {
        std::ofstream out(path, std::ios::binary);
        out << prefixes[k];
        for (size_t i = 0; i < size; ++i) out.put(next_byte());
      }
      std::vector<BagRecord> records;
      const Status status = ReadAll(path, BagReaderOptions(), &records);
      EXPECT_FALSE(status.ok()) << path;
      EXPECT_TRUE(Contains(status.message(), path)) << status.message();
    }
  }
}

TEST(BagReaderErrorTest, TruncatedBagIsAnErrorWithoutRecovery) {
  TempDir dir;
  const std::string path = dir.File("full.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 400, 200);
  const uintmax_t size = std::filesystem::file_size(path);
  BagReaderOptions no_recovery;
  no_recovery.recover_damaged_bags = false;
  for (double fraction : {0.5, 0.0, 0.001, 0.25, 0.75, 0.99}) {
    const std::string cut = dir.File("cut.bag");
    std::filesystem::copy_file(path, cut, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(cut, static_cast<uintmax_t>(size * fraction));
    std::vector<BagRecord> records;
    const Status status = ReadAll(cut, no_recovery, &records);
    EXPECT_FALSE(status.ok()) << fraction;
    EXPECT_TRUE(Contains(status.message(), cut)) << status.message();
    if (fraction > 0.01) {
      EXPECT_TRUE(Contains(status.message(), "truncated")) << status.message();
      EXPECT_TRUE(Contains(status.message(), "recover_damaged_bags")) << status.message();
    }
    // A file cut inside its file header has nothing to recover.
    if (fraction < 0.01) {
      EXPECT_FALSE(ReadAll(cut, BagReaderOptions(), &records).ok());
    }
  }
  // The last byte missing.
  const std::string cut = dir.File("cut1.bag");
  std::filesystem::copy_file(path, cut);
  std::filesystem::resize_file(cut, size - 1);
  std::vector<BagRecord> records;
  EXPECT_FALSE(ReadAll(cut, no_recovery, &records).ok());
}

// Overwrites 16 bytes at ~150 places of a valid bag (record headers, chunk
// headers, index data, message data), uncompressed and LZ4: reading must end
// in Ok or an error Status, never crash or overrun (the ASan build checks).
TEST(BagReaderErrorTest, OverwrittenBytesNeverCrash) {
  TempDir dir;
  for (BagCompression compression : {BagCompression::kNone, BagCompression::kLz4}) {
    const std::string path = dir.File("full.bag");
    BagWriterOptions options;
    options.compression = compression;
    testing::WriteSimpleBag(path, options, 60, 50);
    std::ifstream in(path, std::ios::binary);
    const std::string original((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    const size_t stride = std::max<size_t>(1, original.size() / 150);
    int errors = 0;
    for (size_t at = 0; at + 16 <= original.size(); at += stride) {
      const char fill = (at / stride) % 2 == 0 ? '\xff' : '\x00';
      std::string bytes = original;
      for (size_t i = 0; i < 16; ++i) bytes[at + i] = fill;
      const std::string corrupt = dir.File("corrupt.bag");
      {
        std::ofstream out(corrupt, std::ios::binary | std::ios::trunc);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      }
      std::vector<BagRecord> records;
      BagReaderOptions read_options;
      read_options.skip_malformed_messages = (at / stride) % 3 == 0;
      const Status status = ReadAll(corrupt, read_options, &records);
      if (!status.ok()) {
        ++errors;
        EXPECT_TRUE(Contains(status.message(), corrupt)) << status.message();
      }
    }
    EXPECT_GT(errors, 0);
  }
}

TEST(BagReaderErrorTest, UnindexedBagIsReported) {
  TempDir dir;
  const std::string path = dir.File("unindexed.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 20);
  {
    // A recorder killed before closing leaves index_pos = 0 in the file header.
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    std::string head(4096, '\0');
    file.read(head.data(), static_cast<std::streamsize>(head.size()));
    const size_t at = head.find("index_pos=");
    ASSERT_NE(at, std::string::npos);
    file.clear();
    file.seekp(static_cast<std::streamoff>(at + 10));
    const char zeros[8] = {};
    file.write(zeros, sizeof(zeros));
  }
  BagReaderOptions no_recovery;
  no_recovery.recover_damaged_bags = false;
  std::unique_ptr<BagReader> reader;
  const Status status = BagReader::Open(path, no_recovery, &reader);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_TRUE(Contains(status.message(), "not indexed")) << status.message();
  BagInfo info;
  EXPECT_FALSE(ReadBagInfo(path, &info, /*recover_damaged_bags=*/false).ok());
  // By default every message is recovered (bag_recovery_test.cc has more).
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(path, BagReaderOptions(), &records, &stats).ok());
  EXPECT_EQ(stats.imu_samples, 20);
  EXPECT_TRUE(stats.recovery.recovered);
  EXPECT_TRUE(Contains(stats.recovery.reason, "not indexed")) << stats.recovery.reason;
  ASSERT_TRUE(ReadBagInfo(path, &info).ok());
  EXPECT_TRUE(info.recovery.recovered);
  EXPECT_EQ(info.message_count, 20 + 1 + 2);
}

TEST(BagReaderErrorTest, MissingTopicsListTheBagsTopics) {
  TempDir dir;
  const std::string path = dir.File("topics.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 30);
  {
    // An IMU topic and a LiDAR topic of no supported type.
    rosbag::Bag bag;
    bag.open(dir.File("no_lidar.bag"), rosbag::bagmode::Write);
    sensor_msgs::Imu imu;
    bag.write("/livox/imu", T(5), imu);
    geometry_msgs::PoseStamped pose;
    bag.write("/livox/lidar", T(5), pose);
    bag.close();
  }
  std::unique_ptr<BagReader> reader;
  BagReaderOptions options;
  options.lidar_topic = "/velodyne_points";
  Status status = BagReader::Open(dir.File("no_lidar.bag"), options, &reader);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_TRUE(Contains(status.message(), "lidar_topic '/velodyne_points' not found"))
      << status.message();
  EXPECT_TRUE(Contains(status.message(), "/livox/imu [sensor_msgs/Imu]")) << status.message();
  EXPECT_TRUE(Contains(status.message(), "/livox/lidar [geometry_msgs/PoseStamped]"));

  // An absent IMU / LiDAR topic is replaced by the only topic of its type.
  options = BagReaderOptions();
  options.imu_topic = "/imu/data";
  options.lidar_topic = "/velodyne_points";
  ASSERT_TRUE(BagReader::Open(path, options, &reader).ok());
  EXPECT_EQ(reader->imu_topic(), "/livox/imu");
  EXPECT_EQ(reader->lidar_topic(), "/livox/lidar");

  // A missing ground-truth topic is fine.
  options = BagReaderOptions();
  options.ground_truth_topic = "/vicon/pose";
  ASSERT_TRUE(BagReader::Open(path, options, &reader).ok());
  EXPECT_FALSE(reader->has_ground_truth());
  EXPECT_EQ(reader->ground_truth_topic(), "");
  options.ground_truth_topic = "";
  ASSERT_TRUE(BagReader::Open(path, options, &reader).ok());
  EXPECT_FALSE(reader->has_ground_truth());
}

TEST(BagReaderErrorTest, WrongTypesAreInvalidArgument) {
  TempDir dir;
  const std::string path = dir.File("wrong.bag");
  {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Write);
    sensor_msgs::Imu imu;
    imu.header.stamp = T(5);
    bag.write("/livox/imu", T(5), imu);
    bag.write("/livox/lidar", T(5), imu);  // IMU on the LiDAR topic
    geometry_msgs::PoseStamped pose;
    bag.write("/pose", T(5), pose);
    RawMessage fake;  // right type name, wrong MD5
    fake.datatype = "sensor_msgs/Imu";
    fake.md5sum = "0123456789abcdef0123456789abcdef";
    fake.bytes = testing::Serialize(imu);
    bag.write("/fake_imu", T(5), fake);
    bag.close();
  }
  std::unique_ptr<BagReader> reader;
  Status status = BagReader::Open(path, BagReaderOptions(), &reader);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "lidar_topic '/livox/lidar' has type sensor_msgs/Imu"))
      << status.message();

  BagReaderOptions options;
  options.lidar_topic = "/pose";
  status = BagReader::Open(path, options, &reader);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);

  options = BagReaderOptions();
  options.imu_topic = "/fake_imu";
  status = BagReader::Open(path, options, &reader);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "MD5")) << status.message();

  options = BagReaderOptions();
  options.lidar_topic = "/pose";
  options.ground_truth_topic = "/livox/imu";
  options.imu_topic = "/livox/lidar";
  EXPECT_FALSE(BagReader::Open(path, options, &reader).ok());
}

TEST(BagReaderErrorTest, NonFiniteValuesAreSkippedAndCounted) {
  TempDir dir;
  const std::string path = dir.File("nan.bag");
  {
    std::unique_ptr<BagWriter> writer;
    ASSERT_TRUE(BagWriter::Open(path, BagWriterOptions(), &writer).ok());
    for (int i = 0; i < 10; ++i) {
      ImuSample imu = MakeImu(i, 1000 + i);
      if (i == 3) imu.angular_velocity_rad_s.y() = kNaN;
      if (i == 6) imu.linear_acceleration.z() = std::numeric_limits<double>::infinity();
      ASSERT_TRUE(writer->WriteImu(imu).ok());
    }
    LidarScan partly = MakeLivoxScan(0, 2000, 10);
    partly.points[2].x = std::nanf("");
    partly.points[5].z = std::numeric_limits<float>::infinity();
    partly.points[9].y = -std::numeric_limits<float>::infinity();
    ASSERT_TRUE(writer->WriteScan(partly).ok());
    LidarScan all_nan = MakeLivoxScan(1, 3000, 4);
    for (LidarPoint& p : all_nan.points) p.x = std::nanf("");
    ASSERT_TRUE(writer->WriteScan(all_nan).ok());
    PoseStamped pose = MakePose(0, 4000);
    pose.q_G_b.coeffs()[3] = kNaN;
    ASSERT_TRUE(writer->WriteGroundTruth(pose).ok());
    ASSERT_TRUE(writer->WriteGroundTruth(MakePose(1, 5000)).ok());
    ASSERT_TRUE(writer->Close().ok());
  }
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(path, BagReaderOptions(), &records, &stats).ok());
  EXPECT_EQ(stats.imu_samples, 8);
  EXPECT_EQ(stats.Skipped(SkipReason::kImuNonFinite), 2);
  EXPECT_EQ(stats.scans, 1);
  EXPECT_EQ(stats.points, 7);
  EXPECT_EQ(stats.Skipped(SkipReason::kPointNonFinite), 3 + 4);
  EXPECT_EQ(stats.Skipped(SkipReason::kScanEmpty), 1);
  EXPECT_EQ(stats.ground_truth_poses, 1);
  EXPECT_EQ(stats.Skipped(SkipReason::kPoseNonFinite), 1);
  const auto scans = Select<LidarScan>(records);
  ASSERT_EQ(scans.size(), 1u);
  for (const LidarPoint& p : scans[0].points) {
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
  for (const ImuSample& imu : Select<ImuSample>(records)) {
    EXPECT_TRUE(imu.angular_velocity_rad_s.allFinite() && imu.linear_acceleration.allFinite());
  }
}

TEST(BagReaderErrorTest, StampsGoingBackwardsAreSkippedAndCounted) {
  TempDir dir;
  const std::string path = dir.File("backwards.bag");
  // Bag (record) time increases; header stamps go back once per topic.
  const std::vector<int64_t> imu_stamps = {100, 200, 300, 250, 300, 400};
  const std::vector<int64_t> scan_stamps = {1000, 2000, 1500, 3000};
  const std::vector<int64_t> pose_stamps = {10, 5, 20};
  {
    std::unique_ptr<BagWriter> writer;
    ASSERT_TRUE(BagWriter::Open(path, BagWriterOptions(), &writer).ok());
    for (size_t i = 0; i < imu_stamps.size(); ++i) {
      ASSERT_TRUE(writer->WriteImu(MakeImu(i, imu_stamps[i]), 100 * (i + 1)).ok());
    }
    for (size_t i = 0; i < scan_stamps.size(); ++i) {
      ASSERT_TRUE(writer->WriteScan(MakeLivoxScan(i, scan_stamps[i], 3), 1000 * (i + 1)).ok());
    }
    for (size_t i = 0; i < pose_stamps.size(); ++i) {
      ASSERT_TRUE(writer->WriteGroundTruth(MakePose(i, pose_stamps[i]), 10 * (i + 1)).ok());
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(path, BagReaderOptions(), &records, &stats).ok());
  EXPECT_EQ(stats.Skipped(SkipReason::kImuNonMonotonic), 1);
  EXPECT_EQ(stats.Skipped(SkipReason::kScanNonMonotonic), 1);
  EXPECT_EQ(stats.Skipped(SkipReason::kPoseNonMonotonic), 1);
  std::vector<int64_t> imu_read, scan_read;
  for (const auto& imu : Select<ImuSample>(records)) imu_read.push_back(imu.stamp_ns);
  for (const auto& scan : Select<LidarScan>(records)) scan_read.push_back(scan.stamp_ns);
  EXPECT_EQ(imu_read, (std::vector<int64_t>{100, 200, 300, 300, 400}));  // equal is kept
  EXPECT_EQ(scan_read, (std::vector<int64_t>{1000, 2000, 3000}));
  EXPECT_EQ(Select<PoseStamped>(records).size(), 2u);
}

TEST(BagReaderErrorTest, EmptyScansAreSkippedAndCounted) {
  TempDir dir;
  for (LidarMessageFormat format : {LidarMessageFormat::kLivoxCustomMsg, LidarMessageFormat::kPointCloud2}) {
    const std::string path = dir.File("empty.bag");
    BagWriterOptions options;
    options.lidar_format = format;
    {
      std::unique_ptr<BagWriter> writer;
      ASSERT_TRUE(BagWriter::Open(path, options, &writer).ok());
      ASSERT_TRUE(writer->WriteImu(MakeImu(0, 1)).ok());
      ASSERT_TRUE(writer->WriteScan(testing::MakeScan(0, 10, 0)).ok());
      ASSERT_TRUE(writer->WriteScan(testing::MakeScan(1, 20, 5)).ok());
      ASSERT_TRUE(writer->Close().ok());
    }
    std::vector<BagRecord> records;
    ReadStats stats;
    ASSERT_TRUE(ReadAll(path, BagReaderOptions(), &records, &stats).ok());
    EXPECT_EQ(stats.Skipped(SkipReason::kScanEmpty), 1);
    EXPECT_EQ(stats.scans, 1);
    EXPECT_EQ(stats.points, 5);
  }
}

TEST(BagReaderErrorTest, CloudWithoutTimeFieldIsReadAsOneInstant) {
  TempDir dir;
  const std::string path = dir.File("notime.bag");
  {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Write);
    sensor_msgs::Imu imu;
    imu.header.stamp = T(5);
    bag.write("/livox/imu", T(5), imu);
    for (int s = 0; s < 3; ++s) {
      sensor_msgs::PointCloud2 cloud;
      cloud.header.stamp = T(100 + s);
      cloud.height = 1;
      cloud.width = 4;
      cloud.point_step = 12;
      cloud.row_step = 48;
      for (const char* name : {"x", "y", "z"}) {
        sensor_msgs::PointField f;
        f.name = name;
        f.offset = static_cast<uint32_t>(4 * cloud.fields.size());
        f.datatype = sensor_msgs::PointField::FLOAT32;
        f.count = 1;
        cloud.fields.push_back(f);
      }
      cloud.data.assign(48, 0);
      bag.write("/livox/lidar", T(100 + s), cloud);
    }
    bag.close();
  }
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(path, BagReaderOptions(), &records, &stats).ok());
  const auto scans = Select<LidarScan>(records);
  ASSERT_EQ(scans.size(), 3u);
  for (const LidarScan& scan : scans) {
    ASSERT_EQ(scan.points.size(), 4u);
    for (const LidarPoint& p : scan.points) EXPECT_EQ(p.offset_time_s, 0.0);
  }
  EXPECT_EQ(stats.scans_without_point_time, 3);
  EXPECT_EQ(stats.TotalSkipped(), 0);
}

TEST(BagReaderErrorTest, CorruptMessageBytesAreADecodeErrorOrACountedSkip) {
  TempDir dir;
  const std::string path = dir.File("corrupt.bag");
  {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Write);
    sensor_msgs::Imu imu;
    ASSERT_TRUE(internal::EncodeImu(MakeImu(0, 5), 0, &imu).ok());
    bag.write("/livox/imu", T(5), imu);
    bag.write("/livox/lidar", T(10), CustomMsgBytes(MakeLivoxScan(0, 10, 5)));
    RawMessage lying_num = CustomMsgBytes(MakeLivoxScan(1, 20, 5));
    lying_num.bytes[4 + 8 + 4 + 11 + 8] = 9;  // point_num (frame "livox_frame")
    bag.write("/livox/lidar", T(20), lying_num);
    RawMessage lying_length = CustomMsgBytes(MakeLivoxScan(2, 30, 5));
    const size_t length_at = lying_length.bytes.size() - 5 * 19 - 4;
    lying_length.bytes[length_at + 3] = 0x7f;  // ~2^31 points
    bag.write("/livox/lidar", T(30), lying_length);
    RawMessage truncated = CustomMsgBytes(MakeLivoxScan(3, 40, 5));
    truncated.bytes.resize(truncated.bytes.size() - 7);
    bag.write("/livox/lidar", T(40), truncated);
    bag.write("/livox/lidar", T(50), CustomMsgBytes(MakeLivoxScan(4, 50, 5)));
    bag.close();
  }
  {
    std::unique_ptr<BagReader> reader;
    ASSERT_TRUE(BagReader::Open(path, BagReaderOptions(), &reader).ok());
    BagRecord record;
    bool has_record = false;
    Status status;
    int delivered = 0;
    while ((status = reader->Next(&record, &has_record)).ok() && has_record) ++delivered;
    EXPECT_EQ(status.code(), Status::Code::kDataLoss);
    EXPECT_TRUE(Contains(status.message(), path));
    EXPECT_TRUE(Contains(status.message(), "/livox/lidar"));
    EXPECT_TRUE(Contains(status.message(), "point_num")) << status.message();
    EXPECT_EQ(delivered, 2);  // the IMU sample and the first scan
    EXPECT_EQ(reader->Next(&record, &has_record).code(), Status::Code::kFailedPrecondition);
  }
  BagReaderOptions options;
  options.skip_malformed_messages = true;
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(path, options, &records, &stats).ok());
  EXPECT_EQ(stats.Skipped(SkipReason::kMalformedMessage), 3);
  EXPECT_EQ(stats.scans, 2);
  EXPECT_EQ(stats.imu_samples, 1);
}

TEST(BagReaderErrorTest, InvalidOptionsAreRejected) {
  TempDir dir;
  const std::string path = dir.File("ok.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 5);
  std::unique_ptr<BagReader> reader;
  BagReaderOptions options;
  options.imu_topic = "/same";
  options.lidar_topic = "/same";
  Status status = BagReader::Open(path, options, &reader);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "imu_topic"));
  options = BagReaderOptions();
  options.max_message_mib = 0;
  EXPECT_EQ(BagReader::Open(path, options, &reader).code(), Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::io
