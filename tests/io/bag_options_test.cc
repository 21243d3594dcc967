#include "swarmlio/io/bag_options.h"

#include <gtest/gtest.h>

#include <string>

#include "swarmlio/io/read_stats.h"

namespace swarmlio::io {
namespace {

TEST(BagOptionsTest, DefaultsAreValid) {
  EXPECT_EQ(BagReaderOptions().Validate(), "");
  EXPECT_EQ(BagWriterOptions().Validate(), "");
  EXPECT_EQ(BagReaderOptions().imu_topic, "/livox/imu");
  EXPECT_EQ(BagReaderOptions().lidar_topic, "/livox/lidar");
  EXPECT_EQ(BagReaderOptions().ground_truth_topic, "/ground_truth/pose");
  EXPECT_EQ(BagReaderOptions().point_time_field, "");
}

TEST(BagOptionsTest, ValidateNamesTheKey) {
  BagReaderOptions reader;
  reader.lidar_topic = reader.imu_topic;
  EXPECT_NE(reader.Validate().find("lidar_topic"), std::string::npos);
  reader = BagReaderOptions();
  reader.max_message_mib = -1;
  EXPECT_NE(reader.Validate().find("max_message_mib"), std::string::npos);

  BagWriterOptions writer;
  writer.point_time_field = "x";
  EXPECT_NE(writer.Validate().find("point_time_field"), std::string::npos);
  writer = BagWriterOptions();
  writer.ground_truth_topic = writer.lidar_topic;
  EXPECT_NE(writer.Validate(), "");
}

TEST(BagOptionsTest, EnumNamesRoundTrip) {
  for (const char* name : {"s", "ms", "us", "ns"}) {
    TimestampUnit unit = TimestampUnit::kSecond;
    ASSERT_TRUE(config::EnumFromString(name, &unit)) << name;
    EXPECT_STREQ(config::EnumToString(unit), name);
  }
  EXPECT_EQ(config::EnumChoices<TimestampUnit>(), "s, ms, us, ns");
  TimestampUnit unit = TimestampUnit::kSecond;
  EXPECT_FALSE(config::EnumFromString("seconds", &unit));
  EXPECT_EQ(TimestampUnitTicksPerSecond(TimestampUnit::kSecond), 1.0);
  EXPECT_EQ(TimestampUnitTicksPerSecond(TimestampUnit::kMillisecond), 1e3);
  EXPECT_EQ(TimestampUnitTicksPerSecond(TimestampUnit::kMicrosecond), 1e6);
  EXPECT_EQ(TimestampUnitTicksPerSecond(TimestampUnit::kNanosecond), 1e9);
  LidarMessageFormat format = LidarMessageFormat::kLivoxCustomMsg;
  ASSERT_TRUE(config::EnumFromString("pointcloud2", &format));
  EXPECT_EQ(format, LidarMessageFormat::kPointCloud2);
  BagCompression compression = BagCompression::kNone;
  ASSERT_TRUE(config::EnumFromString("lz4", &compression));
  EXPECT_EQ(compression, BagCompression::kLz4);
}

TEST(BagOptionsTest, OptionsAreVisitable) {
  static_assert(config::IsOptionsStruct<BagReaderOptions>::value);
  static_assert(config::IsOptionsStruct<BagWriterOptions>::value);
  int count = 0;
  BagReaderOptions options;
  options.VisitFields([&count](const char*, auto&, const config::FieldSpec&) { ++count; });
  EXPECT_EQ(count, 12);  // + reconstruct_point_time, spinning_lidar
}

TEST(BagOptionsTest, EmptyOrAutoTopicsAreValid) {
  BagReaderOptions reader;
  reader.imu_topic = "";
  reader.lidar_topic = "auto";
  reader.ground_truth_topic = "auto";
  EXPECT_EQ(reader.Validate(), "");
  reader.imu_topic = "auto";
  EXPECT_EQ(reader.Validate(), "");  // two "auto" topics do not clash
  EXPECT_TRUE(IsAutoTopic(""));
  EXPECT_TRUE(IsAutoTopic("auto"));
  EXPECT_FALSE(IsAutoTopic("/auto"));
  EXPECT_TRUE(BagReaderOptions().check_point_time_span);
  EXPECT_TRUE(BagReaderOptions().recover_damaged_bags);
  GroundTruthFormat format = GroundTruthFormat::kPoseStamped;
  ASSERT_TRUE(config::EnumFromString("odometry", &format));
  EXPECT_EQ(format, GroundTruthFormat::kOdometry);
  EXPECT_EQ(BagWriterOptions().ground_truth_format, GroundTruthFormat::kPoseStamped);
}

TEST(ReadStatsTest, NamesAndSummary) {
  ReadStats stats;
  stats.skipped[static_cast<size_t>(SkipReason::kScanEmpty)] = 2;
  stats.skipped[static_cast<size_t>(SkipReason::kImuNonFinite)] = 1;
  EXPECT_EQ(stats.TotalSkipped(), 3);
  EXPECT_STREQ(SkipReasonName(SkipReason::kMalformedMessage), "malformed_message");
  EXPECT_NE(stats.ToString().find("skipped.scan_empty: 2"), std::string::npos);
  EXPECT_STREQ(SkipReasonName(SkipReason::kDamagedRecord), "damaged_record");
  EXPECT_EQ(stats.ToString().find("recovery:"), std::string::npos);
  EXPECT_EQ(stats.recovery.Summary(), "");
  stats.recovery.recovered = true;
  stats.recovery.reason = "bag is not indexed";
  stats.recovery.messages = 40;
  stats.recovery.damaged_records = 1;
  stats.recovery.damaged_bytes = 77;
  stats.recovery.damage_offset = 9000;
  EXPECT_EQ(stats.recovery.Summary(),
            "recovered 40 messages by scanning the records (bag is not indexed); 1 damaged "
            "records, 77 bytes unreadable from offset 9000");
  EXPECT_NE(stats.ToString().find("recovery: recovered 40 messages"), std::string::npos);
}

}  // namespace
}  // namespace swarmlio::io
