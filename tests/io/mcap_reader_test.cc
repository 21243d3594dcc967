// MCAP (ROS 2) logs through BagReader and ReadBagInfo: files from our writer
// read back exactly like the same records in a ROS1 bag; hand-built files
// (tests/io/mcap_test_util.h) with zstd, lz4 and uncompressed chunks; bad
// chunk CRCs, truncated and unfinished files give every complete record
// before the damage; overwritten bytes never crash.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "src/io/cdr_serialize.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/message_types.h"
#include "src/io/pose_codec.h"
#include "swarmlio/io/bag_info.h"
#include "tests/io/bag_test_util.h"
#include "tests/io/mcap_test_util.h"

namespace swarmlio::io {
namespace {

using testing::Bytes;
using testing::McapBuilder;
using testing::ReadAll;
using testing::Select;
using testing::TempDir;

constexpr int64_t kT0 = 1000000000;
constexpr int64_t kImuPeriodNs = 5000000;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

void WriteFile(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

Bytes ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

Bytes ImuCdr(int i) {
  sensor_msgs::Imu msg;
  EXPECT_TRUE(internal::EncodeImu(testing::MakeImu(i, kT0 + i * kImuPeriodNs), 0, &msg).ok());
  Bytes bytes;
  internal::SerializeCdr(msg, &bytes);
  return bytes;
}

Bytes ScanCdr(int i) {
  internal::LivoxCustomMsg msg;
  const LidarScan scan = testing::MakeLivoxScan(i, kT0 + i * kImuPeriodNs, 15);
  EXPECT_TRUE(internal::EncodeLivoxCustomMsg(scan, 0, &msg).ok());
  Bytes bytes;
  internal::SerializeCdr(msg, &bytes);
  return bytes;
}

// Schemas and channels: 0 /livox/imu, 1 /livox/lidar, 2 /ground_truth/pose.
std::vector<std::pair<uint8_t, Bytes>> Definitions() {
  return {{0x03, McapBuilder::Schema(1, "sensor_msgs/msg/Imu", "ros2msg")},
          {0x03, McapBuilder::Schema(2, "livox_ros_driver2/msg/CustomMsg", "ros2msg")},
          {0x04, McapBuilder::Channel(0, 1, "/livox/imu", "cdr")},
          {0x04, McapBuilder::Channel(1, 2, "/livox/lidar", "cdr")}};
}

// Message i: IMU sample i, and a scan after every 10th sample.
std::vector<std::pair<uint8_t, Bytes>> Messages(int i) {
  const uint64_t t = static_cast<uint64_t>(kT0 + i * kImuPeriodNs);
  std::vector<std::pair<uint8_t, Bytes>> records = {{0x05, McapBuilder::Message(0, t, ImuCdr(i))}};
  if (i % 10 == 0) records.push_back({0x05, McapBuilder::Message(1, t, ScanCdr(i))});
  return records;
}

TEST(McapReaderTest, WrittenMcapReadsBackLikeTheRos1Bag) {
  TempDir dir;
  struct Case {
    LidarMessageFormat lidar;
    GroundTruthFormat ground_truth;
    BagCompression compression;
  };
  for (const Case& c :
       {Case{LidarMessageFormat::kLivoxCustomMsg, GroundTruthFormat::kPoseStamped,
             BagCompression::kNone},
        Case{LidarMessageFormat::kPointCloud2, GroundTruthFormat::kOdometry, BagCompression::kZstd},
        Case{LidarMessageFormat::kLivoxCustomMsg, GroundTruthFormat::kOdometry,
             BagCompression::kLz4}}) {
    BagWriterOptions options;
    options.lidar_format = c.lidar;
    options.ground_truth_format = c.ground_truth;
    BagWriterOptions ros1 = options;
    ros1.compression = BagCompression::kNone;
    options.compression = c.compression;
    testing::WriteSimpleBag(dir.File("run.bag"), ros1, 300, 40);
    testing::WriteSimpleBag(dir.File("run.mcap"), options, 300, 40);
    std::vector<BagRecord> from_bag, from_mcap;
    ReadStats bag_stats, mcap_stats;
    ASSERT_TRUE(ReadAll(dir.File("run.bag"), BagReaderOptions(), &from_bag, &bag_stats).ok());
    const Status status =
        ReadAll(dir.File("run.mcap"), BagReaderOptions(), &from_mcap, &mcap_stats);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(from_mcap.size(), 300u + 15u + 30u);
    testing::ExpectSameRecords(from_mcap, from_bag);
    EXPECT_EQ(mcap_stats.ToString(), bag_stats.ToString());
    EXPECT_FALSE(mcap_stats.recovery.recovered);

    BagInfo bag_info, mcap_info;
    ASSERT_TRUE(ReadBagInfo(dir.File("run.bag"), &bag_info).ok());
    ASSERT_TRUE(ReadBagInfo(dir.File("run.mcap"), &mcap_info).ok());
    EXPECT_EQ(mcap_info.message_count, bag_info.message_count);
    EXPECT_EQ(mcap_info.start_time_ns, bag_info.start_time_ns);
    EXPECT_EQ(mcap_info.end_time_ns, bag_info.end_time_ns);
    ASSERT_EQ(mcap_info.topics.size(), 3u);
    EXPECT_EQ(mcap_info.topics[1].topic, "/livox/imu");
    EXPECT_EQ(mcap_info.topics[1].datatype, "sensor_msgs/msg/Imu");
    EXPECT_EQ(mcap_info.topics[1].message_count, 300);
  }
}

TEST(McapReaderTest, FormatIsToldByTheMagicBytesNotTheExtension) {
  TempDir dir;
  BagWriterOptions mcap;
  mcap.format = BagFormat::kMcap;
  testing::WriteSimpleBag(dir.File("really_mcap.bag"), mcap, 40);
  BagWriterOptions ros1;
  ros1.format = BagFormat::kRos1;
  testing::WriteSimpleBag(dir.File("really_ros1.mcap"), ros1, 40);
  std::vector<BagRecord> a, b;
  ASSERT_TRUE(ReadAll(dir.File("really_mcap.bag"), BagReaderOptions(), &a).ok());
  ASSERT_TRUE(ReadAll(dir.File("really_ros1.mcap"), BagReaderOptions(), &b).ok());
  testing::ExpectSameRecords(a, b);
  BagInfo info;
  ASSERT_TRUE(ReadBagInfo(dir.File("really_mcap.bag"), &info).ok());
  EXPECT_EQ(info.topics[0].datatype, "geometry_msgs/msg/PoseStamped");
  // Compressions of the other format are refused.
  std::unique_ptr<BagWriter> writer;
  mcap.compression = BagCompression::kBz2;
  EXPECT_EQ(BagWriter::Open(dir.File("x.mcap"), mcap, &writer).code(),
            Status::Code::kInvalidArgument);
  ros1.compression = BagCompression::kZstd;
  EXPECT_EQ(BagWriter::Open(dir.File("x.bag"), ros1, &writer).code(),
            Status::Code::kInvalidArgument);
}

TEST(McapReaderTest, HandBuiltZstdLz4AndUncompressedChunksAreRead) {
  TempDir dir;
  McapBuilder builder;
  std::vector<std::pair<uint8_t, Bytes>> first = Definitions();  // definitions inside a chunk
  for (int i = 0; i < 30; ++i) {
    for (auto& r : Messages(i)) first.push_back(std::move(r));
  }
  builder.AddChunk(first, "zstd");
  std::vector<std::pair<uint8_t, Bytes>> second, third;
  for (int i = 30; i < 60; ++i) {
    for (auto& r : Messages(i)) second.push_back(std::move(r));
  }
  for (int i = 60; i < 90; ++i) {
    for (auto& r : Messages(i)) third.push_back(std::move(r));
  }
  builder.AddChunk(second, "lz4");
  builder.AddChunk(third, "", /*crc=*/false);
  WriteFile(dir.File("hand.mcap"), builder.Finish());
  std::vector<BagRecord> records;
  ReadStats stats;
  const Status status = ReadAll(dir.File("hand.mcap"), BagReaderOptions(), &records, &stats);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::vector<ImuSample> imu = Select<ImuSample>(records);
  const std::vector<LidarScan> scans = Select<LidarScan>(records);
  ASSERT_EQ(imu.size(), 90u);
  ASSERT_EQ(scans.size(), 9u);
  for (int i = 0; i < 90; ++i) {
    testing::ExpectImuEqual(imu[i], testing::MakeImu(i, kT0 + i * kImuPeriodNs));
  }
  testing::ExpectScanEqual(scans[8], testing::MakeLivoxScan(80, kT0 + 80 * kImuPeriodNs, 15));
  EXPECT_FALSE(stats.recovery.recovered);
}

TEST(McapReaderTest, ChunkWithABadCrcIsSkippedAndCounted) {
  TempDir dir;
  McapBuilder builder;
  for (const auto& [op, content] : Definitions()) builder.Add(op, content);
  for (int c = 0; c < 3; ++c) {
    std::vector<std::pair<uint8_t, Bytes>> records;
    for (int i = 30 * c; i < 30 * (c + 1); ++i) {
      for (auto& r : Messages(i)) records.push_back(std::move(r));
    }
    builder.AddChunk(records, c == 1 ? "zstd" : "");
  }
  Bytes bytes = builder.Finish();
  // The second chunk's CRC field (8+8+8 bytes into its content), found by
  // walking the records.
  size_t at = 8;
  int chunks = 0;
  size_t crc_at = 0;
  while (at < bytes.size() - 8) {
    const uint8_t op = bytes[at];
    uint64_t length = 0;
    for (int k = 0; k < 8; ++k) length |= static_cast<uint64_t>(bytes[at + 1 + k]) << (8 * k);
    if (op == 0x06 && ++chunks == 2) crc_at = at + 9 + 24;
    at += 9 + length;
  }
  ASSERT_GT(crc_at, 0u);
  bytes[crc_at] ^= 0x5A;
  WriteFile(dir.File("bad_crc.mcap"), bytes);
  std::vector<BagRecord> records;
  ReadStats stats;
  ASSERT_TRUE(ReadAll(dir.File("bad_crc.mcap"), BagReaderOptions(), &records, &stats).ok());
  EXPECT_EQ(Select<ImuSample>(records).size(), 60u);
  EXPECT_TRUE(stats.recovery.recovered);
  EXPECT_EQ(stats.recovery.damaged_records, 1);
  EXPECT_TRUE(Contains(stats.recovery.reason, "CRC")) << stats.recovery.reason;
  BagReaderOptions strict;
  strict.recover_damaged_bags = false;
  const Status status = ReadAll(dir.File("bad_crc.mcap"), strict, &records);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_TRUE(Contains(status.message(), "CRC")) << status.message();
  EXPECT_TRUE(Contains(status.message(), dir.File("bad_crc.mcap"))) << status.message();
}

// One byte changed inside an uncompressed chunk's records (the reader finds
// messages in place there): the chunk's CRC catches it, and a chunk without
// one (CRC 0) is caught by DataEnd's data-section CRC, which the reader
// combines from the chunk header's CRC and the records'.
TEST(McapReaderTest, ChangedByteInAnUncompressedChunkIsCaughtByACrc) {
  TempDir dir;
  for (bool chunk_crc : {true, false}) {
    McapBuilder builder;
    for (const auto& [op, content] : Definitions()) builder.Add(op, content);
    size_t second_end = 0;
    for (int c = 0; c < 3; ++c) {
      std::vector<std::pair<uint8_t, Bytes>> records;
      for (int i = 30 * c; i < 30 * (c + 1); ++i) {
        for (auto& r : Messages(i)) records.push_back(std::move(r));
      }
      const size_t end = builder.AddChunk(records, "", chunk_crc);
      if (c == 1) second_end = end;
    }
    Bytes bytes = builder.Finish();
    WriteFile(dir.File("clean.mcap"), bytes);
    std::vector<BagRecord> records;
    ReadStats stats;
    ASSERT_TRUE(ReadAll(dir.File("clean.mcap"), BagReaderOptions(), &records, &stats).ok());
    EXPECT_EQ(Select<ImuSample>(records).size(), 90u);
    EXPECT_FALSE(stats.recovery.recovered) << stats.recovery.reason;

    // The last byte of the second chunk: in IMU sample 59's covariance.
    bytes[second_end - 1] ^= 0x01;
    const std::string corrupt = dir.File("changed.mcap");
    WriteFile(corrupt, bytes);
    stats = ReadStats();
    ASSERT_TRUE(ReadAll(corrupt, BagReaderOptions(), &records, &stats).ok());
    EXPECT_TRUE(stats.recovery.recovered);
    if (chunk_crc) {
      EXPECT_EQ(Select<ImuSample>(records).size(), 60u);  // the chunk is skipped
      EXPECT_TRUE(Contains(stats.recovery.reason, "uncompressed CRC")) << stats.recovery.reason;
    } else {
      EXPECT_EQ(Select<ImuSample>(records).size(), 90u);  // found only at DataEnd
      EXPECT_TRUE(Contains(stats.recovery.reason, "data section CRC")) << stats.recovery.reason;
    }
    BagReaderOptions strict;
    strict.recover_damaged_bags = false;
    const Status status = ReadAll(corrupt, strict, &records);
    EXPECT_EQ(status.code(), Status::Code::kDataLoss);
    EXPECT_TRUE(Contains(status.message(), "CRC")) << status.message();
  }
}

// Cut at many places: unchunked messages count when their record is whole,
// chunked ones when their chunk is.
TEST(McapReaderTest, TruncatedMcapYieldsEveryCompleteRecordBeforeTheCut) {
  TempDir dir;
  for (bool chunked : {false, true}) {
    McapBuilder builder;
    for (const auto& [op, content] : Definitions()) builder.Add(op, content);
    std::vector<std::pair<size_t, int>> imu_ends;  // (offset after, IMU samples complete)
    const size_t start = builder.data_section().size();
    std::vector<std::pair<uint8_t, Bytes>> pending;
    for (int i = 0; i < 60; ++i) {
      for (auto& r : Messages(i)) {
        if (!chunked) {
          imu_ends.push_back({builder.Add(r.first, r.second), i + 1});
        } else {
          pending.push_back(std::move(r));
        }
      }
      if (chunked && i % 10 == 9) {
        imu_ends.push_back({builder.AddChunk(pending, i % 20 == 9 ? "zstd" : "lz4"), i + 1});
        pending.clear();
      }
    }
    const Bytes full = builder.Finish();
    WriteFile(dir.File("full.mcap"), full);
    std::vector<BagRecord> records;
    ASSERT_TRUE(ReadAll(dir.File("full.mcap"), BagReaderOptions(), &records).ok());
    ASSERT_EQ(Select<ImuSample>(records).size(), 60u);
    BagReaderOptions strict;
    strict.recover_damaged_bags = false;
    for (size_t cut = start; cut < full.size(); cut += (full.size() - start) / 37 + 1) {
      int expected = 0;
      for (const auto& [end, count] : imu_ends) {
        if (end <= cut) expected = count;
      }
      const std::string path = dir.File("cut.mcap");
      WriteFile(path, Bytes(full.begin(), full.begin() + static_cast<long>(cut)));
      ReadStats stats;
      const Status status = ReadAll(path, BagReaderOptions(), &records, &stats);
      ASSERT_TRUE(status.ok()) << cut << ": " << status.message();
      EXPECT_EQ(static_cast<int>(Select<ImuSample>(records).size()), expected)
          << (chunked ? "chunked, " : "") << "cut at " << cut;
      EXPECT_TRUE(stats.recovery.recovered) << cut;
      const Status refused = ReadAll(path, strict, &records);
      EXPECT_EQ(refused.code(), Status::Code::kDataLoss) << cut;
      EXPECT_TRUE(Contains(refused.message(), "recover_damaged_bags")) << refused.message();
      EXPECT_TRUE(Contains(refused.message(), "truncated") ||
                  Contains(refused.message(), "unfinished"))
          << refused.message();
    }
    // A writer that died between records: no DataEnd, no footer.
    WriteFile(dir.File("unfinished.mcap"), builder.data_section());
    ReadStats stats;
    ASSERT_TRUE(ReadAll(dir.File("unfinished.mcap"), BagReaderOptions(), &records, &stats).ok());
    EXPECT_EQ(Select<ImuSample>(records).size(), 60u);
    EXPECT_TRUE(Contains(stats.recovery.reason, "unfinished")) << stats.recovery.reason;
    EXPECT_EQ(stats.recovery.damaged_records, 1);
  }
}

TEST(McapReaderTest, ChannelsInAnotherEncodingAreNotTaken) {
  TempDir dir;
  McapBuilder builder;
  builder.Add(0x03, McapBuilder::Schema(1, "sensor_msgs/msg/Imu", "ros2msg"));
  builder.Add(0x03, McapBuilder::Schema(2, "livox_ros_driver2/msg/CustomMsg", "ros2msg"));
  builder.Add(0x04, McapBuilder::Channel(0, 1, "/livox/imu", "json"));
  builder.Add(0x04, McapBuilder::Channel(1, 2, "/livox/lidar", "cdr"));
  WriteFile(dir.File("json.mcap"), builder.Finish());
  std::vector<BagRecord> records;
  Status status = ReadAll(dir.File("json.mcap"), BagReaderOptions(), &records);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "encoding json")) << status.message();
  BagReaderOptions by_type;
  by_type.imu_topic = kAutoTopic;
  status = ReadAll(dir.File("json.mcap"), by_type, &records);
  EXPECT_EQ(status.code(), Status::Code::kNotFound) << status.message();
}

// MCAP can carry ROS1 messages too ("ros1" encoding, ROS1 type names): read
// with the ROS1 decoders when the channel's md5sum metadata matches.
TEST(McapReaderTest, Ros1EncodedChannelsAreReadWithTheirMd5) {
  TempDir dir;
  for (bool with_md5 : {true, false}) {
    McapBuilder builder;
    builder.Add(0x03, McapBuilder::Schema(1, "sensor_msgs/Imu", "ros1msg"));
    builder.Add(0x03, McapBuilder::Schema(2, "livox_ros_driver/CustomMsg", "ros1msg"));
    builder.Add(0x04, McapBuilder::Channel(
                          0, 1, "/livox/imu", "ros1",
                          with_md5 ? internal::ExpectedRos1Md5(internal::MessageKind::kImu) : ""));
    builder.Add(0x04,
                McapBuilder::Channel(1, 2, "/livox/lidar", "ros1", internal::kLivoxCustomMsgMd5));
    for (int i = 0; i < 20; ++i) {
      const int64_t t = kT0 + i * kImuPeriodNs;
      sensor_msgs::Imu imu;
      ASSERT_TRUE(internal::EncodeImu(testing::MakeImu(i, t), 0, &imu).ok());
      builder.Add(0x05, McapBuilder::Message(0, static_cast<uint64_t>(t), testing::Serialize(imu)));
      if (i % 10 == 0) {
        internal::LivoxCustomMsg scan;
        ASSERT_TRUE(
            internal::EncodeLivoxCustomMsg(testing::MakeLivoxScan(i, t, 12), 0, &scan).ok());
        builder.Add(0x05,
                    McapBuilder::Message(1, static_cast<uint64_t>(t), testing::Serialize(scan)));
      }
    }
    WriteFile(dir.File("ros1.mcap"), builder.Finish());
    std::vector<BagRecord> records;
    const Status status = ReadAll(dir.File("ros1.mcap"), BagReaderOptions(), &records);
    if (!with_md5) {
      EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
      EXPECT_TRUE(Contains(status.message(), "MD5")) << status.message();
      continue;
    }
    ASSERT_TRUE(status.ok()) << status.message();
    const std::vector<ImuSample> imu = Select<ImuSample>(records);
    ASSERT_EQ(imu.size(), 20u);
    testing::ExpectImuEqual(imu[7], testing::MakeImu(7, kT0 + 7 * kImuPeriodNs));
    EXPECT_EQ(Select<LidarScan>(records).size(), 2u);
  }
}

// The ROS1 mutation checks (bag_reader_error_test.cc, bag_recovery_test.cc)
// on MCAP: 16 bytes overwritten at ~150 places, some files cut short too;
// reading ends in Ok or an error naming the file, never a crash or overrun.
TEST(McapReaderTest, OverwrittenBytesNeverCrash) {
  TempDir dir;
  for (BagCompression compression :
       {BagCompression::kNone, BagCompression::kZstd, BagCompression::kLz4}) {
    BagWriterOptions options;
    options.compression = compression;
    options.lidar_format = compression == BagCompression::kZstd
                               ? LidarMessageFormat::kPointCloud2
                               : LidarMessageFormat::kLivoxCustomMsg;
    testing::WriteSimpleBag(dir.File("full.mcap"), options, 60, 50);
    const Bytes original = ReadFile(dir.File("full.mcap"));
    const size_t stride = std::max<size_t>(1, original.size() / 150);
    int ok = 0, errors = 0;
    for (size_t at = 0; at + 16 <= original.size(); at += stride) {
      const uint8_t fill = (at / stride) % 2 == 0 ? 0xff : 0x00;
      Bytes bytes = original;
      for (size_t i = 0; i < 16; ++i) bytes[at + i] = fill;
      bytes.resize(bytes.size() - (at / stride) % 5 * 13);
      const std::string corrupt = dir.File("corrupt.mcap");
      WriteFile(corrupt, bytes);
      std::vector<BagRecord> records;
      BagReaderOptions read_options;
      read_options.skip_malformed_messages = (at / stride) % 3 == 0;
      read_options.recover_damaged_bags = (at / stride) % 4 != 0;
      const Status status = ReadAll(corrupt, read_options, &records);
      if (status.ok()) {
        ++ok;
      } else {
        ++errors;
        EXPECT_TRUE(Contains(status.message(), corrupt)) << status.message();
      }
      BagInfo info;
      static_cast<void>(ReadBagInfo(corrupt, &info));
    }
    EXPECT_GT(ok, 0);
    EXPECT_GT(errors, 0);
  }
}

uint64_t Le(const Bytes& bytes, size_t at, size_t n) {
  uint64_t value = 0;
  for (size_t k = 0; k < n; ++k) value |= static_cast<uint64_t>(bytes.at(at + k)) << (8 * k);
  return value;
}

// Our writer's file checked against the spec byte by byte (not with our
// reader, which skips the summary): DataEnd's data CRC, the footer's summary
// CRC, Statistics, and every ChunkIndex pointing at its chunk.
TEST(McapReaderTest, WrittenSummaryAndFooterFollowTheSpec) {
  TempDir dir;
  BagWriterOptions options;
  options.compression = BagCompression::kZstd;
  testing::WriteSimpleBag(dir.File("run.mcap"), options, 2000, 400);  // several chunks
  const Bytes b = ReadFile(dir.File("run.mcap"));
  ASSERT_GT(b.size(), 8u + 9u + 20u + 8u);
  EXPECT_TRUE(std::equal(b.end() - 8, b.end(), b.begin()));  // the magic at both ends
  const size_t footer = b.size() - 8 - 9 - 20;
  ASSERT_EQ(b[footer], 0x02);
  ASSERT_EQ(Le(b, footer + 1, 8), 20u);
  const size_t summary_start = Le(b, footer + 9, 8);
  EXPECT_EQ(Le(b, footer + 17, 8), 0u);
  EXPECT_EQ(Le(b, footer + 25, 4), crc32(0, b.data() + summary_start, footer + 25 - summary_start));
  // DataEnd right before the summary, with the CRC of everything before it.
  const size_t data_end = summary_start - 9 - 4;
  ASSERT_EQ(b[data_end], 0x0F);
  EXPECT_EQ(Le(b, data_end + 9, 4), crc32(0, b.data(), data_end));
  int chunk_indexes = 0;
  for (size_t at = summary_start; at < footer;) {
    const uint64_t length = Le(b, at + 1, 8);
    const size_t content = at + 9;
    if (b[at] == 0x0B) {
      EXPECT_EQ(Le(b, content, 8), 2000u + 100u + 200u);  // message_count
    }
    if (b[at] == 0x08) {
      ++chunk_indexes;
      const size_t chunk = Le(b, content + 16, 8);
      EXPECT_EQ(b.at(chunk), 0x06);
      EXPECT_EQ(Le(b, content + 24, 8), 9 + Le(b, chunk + 1, 8));  // chunk_length
    }
    at = content + length;
    ASSERT_LE(at, footer);
  }
  EXPECT_GT(chunk_indexes, 1);
}

}  // namespace
}  // namespace swarmlio::io
