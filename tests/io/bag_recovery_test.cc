// Reading damaged bags: truncated at many positions (uncompressed, LZ4,
// BZ2), left unindexed by a recorder that died mid-chunk, and corrupted.
// Every complete message before the damage is read (checked exactly against
// where each message's bytes lie in the file), the rest is counted in
// ReadStats::recovery, and nothing crashes (the ASan build checks).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/pose_codec.h"
#include "swarmlio/io/bag_info.h"
#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

using testing::ReadAll;
using testing::Select;
using testing::TempDir;

constexpr int kNumImu = 400;
constexpr int kPointsPerScan = 5000;  // 95 kB scans: the bag has several chunks
constexpr int64_t kT0 = 1000000000;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <class Msg>
std::string Bytes(const Msg& msg) {
  const std::vector<uint8_t> bytes = testing::Serialize(msg);
  return std::string(bytes.begin(), bytes.end());
}

// Where the data of each message WriteSimpleBag wrote ends in the file
// (its serialized bytes are unique), per topic in write order.
struct MessageEnds {
  std::vector<size_t> imu, scans, poses;
};

MessageEnds FindMessageEnds(const std::string& file) {
  MessageEnds ends;
  auto find_end = [&file](const std::string& bytes) {
    const size_t at = file.find(bytes);
    EXPECT_NE(at, std::string::npos);
    EXPECT_EQ(file.find(bytes, at + 1), std::string::npos);
    return at + bytes.size();
  };
  uint32_t scan_seq = 0;
  uint32_t pose_seq = 0;
  for (int i = 0; i < kNumImu; ++i) {
    const int64_t stamp = kT0 + i * 5000000LL;
    sensor_msgs::Imu imu;
    EXPECT_TRUE(internal::EncodeImu(testing::MakeImu(i, stamp), i, &imu).ok());
    ends.imu.push_back(find_end(Bytes(imu)));
    if (i % 20 == 0) {
      internal::LivoxCustomMsg scan;
      EXPECT_TRUE(internal::EncodeLivoxCustomMsg(testing::MakeLivoxScan(i, stamp, kPointsPerScan),
                                                 scan_seq++, &scan)
                      .ok());
      ends.scans.push_back(find_end(Bytes(scan)));
    }
    if (i % 10 == 0) {
      geometry_msgs::PoseStamped pose;
      EXPECT_TRUE(internal::EncodePoseStamped(testing::MakePose(i, stamp), pose_seq++, &pose).ok());
      ends.poses.push_back(find_end(Bytes(pose)));
    }
  }
  return ends;
}

size_t CountBefore(const std::vector<size_t>& ends, size_t cut) {
  return static_cast<size_t>(
      std::count_if(ends.begin(), ends.end(), [cut](size_t end) { return end <= cut; }));
}

uint64_t IndexPos(const std::string& file) {
  const size_t at = file.find("index_pos=");
  EXPECT_NE(at, std::string::npos);
  uint64_t value = 0;
  for (int i = 7; i >= 0; --i) value = (value << 8) | static_cast<uint8_t>(file[at + 10 + i]);
  return value;
}

// As a recorder that died leaves it: index_pos = 0 in the file header.
void ClearIndexPos(std::string* file) {
  const size_t at = file->find("index_pos=");
  ASSERT_NE(at, std::string::npos);
  for (int i = 0; i < 8; ++i) (*file)[at + 10 + i] = '\0';
}

// The stamps of the first `count` records of each kind that WriteSimpleBag
// wrote, checked against what was read.
void ExpectPrefixes(const std::vector<BagRecord>& records,
                    size_t imu,
                    size_t scans,
                    size_t poses,
                    const std::string& context) {
  const auto imus = Select<ImuSample>(records);
  ASSERT_EQ(imus.size(), imu) << context;
  for (size_t k = 0; k < imus.size(); ++k) {
    EXPECT_EQ(imus[k].stamp_ns, kT0 + static_cast<int64_t>(k) * 5000000LL) << context;
  }
  const auto scan_records = Select<LidarScan>(records);
  ASSERT_EQ(scan_records.size(), scans) << context;
  for (size_t k = 0; k < scan_records.size(); ++k) {
    const int i = static_cast<int>(20 * k);
    testing::ExpectScanEqual(scan_records[k],
                             testing::MakeLivoxScan(i, kT0 + i * 5000000LL, kPointsPerScan));
  }
  const auto pose_records = Select<PoseStamped>(records);
  ASSERT_EQ(pose_records.size(), poses) << context;
  for (size_t k = 0; k < pose_records.size(); ++k) {
    const int i = static_cast<int>(10 * k);
    testing::ExpectPoseEqual(pose_records[k], testing::MakePose(i, kT0 + i * 5000000LL));
  }
}

TEST(BagRecoveryTest, TruncatedBagGivesEveryCompleteMessageBeforeTheCut) {
  TempDir dir;
  const std::string path = dir.File("full.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), kNumImu, kPointsPerScan);
  const std::string file = ReadBytes(path);
  const MessageEnds ends = FindMessageEnds(file);
  const uint64_t index_pos = IndexPos(file);
  ASSERT_GT(index_pos, 0u);
  // From just after the first pose (every topic has its connection record)
  // to the end: 40 positions, plus message boundaries and the index.
  std::vector<size_t> cuts;
  const size_t first = ends.poses[0];
  for (int k = 0; k < 40; ++k) cuts.push_back(first + (file.size() - first) * k / 40);
  for (size_t end : {ends.imu[100], ends.scans[7], ends.poses[20]}) {
    cuts.push_back(end);
    cuts.push_back(end + 1);
    cuts.push_back(end - 1);
  }
  cuts.push_back(index_pos);
  cuts.push_back(index_pos + 40);
  cuts.push_back(file.size() - 1);
  int damaged = 0;
  for (size_t cut : cuts) {
    const std::string context =
        "cut at " + std::to_string(cut) + " of " + std::to_string(file.size());
    const std::string cut_path = dir.File("cut.bag");
    WriteBytes(cut_path, file.substr(0, cut));
    std::vector<BagRecord> records;
    ReadStats stats;
    const Status status = ReadAll(cut_path, BagReaderOptions(), &records, &stats);
    ASSERT_TRUE(status.ok()) << context << ": " << status.message();
    const size_t imu = CountBefore(ends.imu, cut);
    const size_t scans = CountBefore(ends.scans, cut);
    const size_t poses = CountBefore(ends.poses, cut);
    ExpectPrefixes(records, imu, scans, poses, context);
    EXPECT_TRUE(stats.recovery.recovered) << context;
    EXPECT_EQ(stats.recovery.messages, static_cast<int64_t>(imu + scans + poses)) << context;
    EXPECT_EQ(stats.Skipped(SkipReason::kDamagedRecord), stats.recovery.damaged_records);
    if (cut < index_pos) {
      EXPECT_TRUE(stats.recovery.reason.find("truncated") != std::string::npos)
          << stats.recovery.reason;
    }
    if (stats.recovery.damaged_records > 0) {
      ++damaged;
      EXPECT_GT(stats.recovery.damage_offset, 0u) << context;
      EXPECT_LE(stats.recovery.damage_offset, cut) << context;
      EXPECT_EQ(stats.recovery.damage_offset + stats.recovery.damaged_bytes, cut) << context;
    }
    // The info summary agrees.
    BagInfo info;
    ASSERT_TRUE(ReadBagInfo(cut_path, &info).ok()) << context;
    EXPECT_EQ(info.message_count, static_cast<int64_t>(imu + scans + poses)) << context;
    EXPECT_TRUE(info.recovery.recovered);
    ASSERT_EQ(info.topics.size(), 3u);
    EXPECT_EQ(info.topics[1].topic, "/livox/imu");
    EXPECT_EQ(info.topics[1].message_count, static_cast<int64_t>(imu));
    if (imu > 0) {
      EXPECT_EQ(info.topics[1].last_time_ns, kT0 + static_cast<int64_t>(imu - 1) * 5000000LL);
    }
  }
  EXPECT_GT(damaged, 30);
}

TEST(BagRecoveryTest, TruncatedCompressedBagsGiveTheirCompleteChunks) {
  TempDir dir;
  for (BagCompression compression : {BagCompression::kLz4, BagCompression::kBz2}) {
    const std::string path = dir.File("full.bag");
    BagWriterOptions options;
    options.compression = compression;
    testing::WriteSimpleBag(path, options, kNumImu, kPointsPerScan);
    const std::string file = ReadBytes(path);
    const uint64_t index_pos = IndexPos(file);
    size_t previous_imu = 0;
    int partial = 0;
    for (int k = 1; k <= 30; ++k) {
      const size_t cut = file.size() * k / 30 - (k == 30 ? 1 : 0);
      const std::string context = std::string(config::EnumToString(compression)) + " cut at " +
                                  std::to_string(cut) + " of " + std::to_string(file.size());
      const std::string cut_path = dir.File("cut.bag");
      WriteBytes(cut_path, file.substr(0, cut));
      std::vector<BagRecord> records;
      ReadStats stats;
      const Status status = ReadAll(cut_path, BagReaderOptions(), &records, &stats);
      if (!status.ok()) {
        // Cut inside the first chunk: no topic survives.
        EXPECT_EQ(status.code(), Status::Code::kNotFound) << context << ": " << status.message();
        EXPECT_EQ(previous_imu, 0u) << context;
        continue;
      }
      const size_t imu = Select<ImuSample>(records).size();
      const size_t scans = Select<LidarScan>(records).size();
      const size_t poses = Select<PoseStamped>(records).size();
      ExpectPrefixes(records, imu, scans, poses, context);  // a prefix of every topic
      EXPECT_GE(imu, previous_imu) << context;
      previous_imu = imu;
      EXPECT_TRUE(stats.recovery.recovered) << context;
      if (cut >= index_pos) {
        EXPECT_EQ(imu, static_cast<size_t>(kNumImu)) << context;
        EXPECT_EQ(stats.recovery.damaged_records, 0) << context;
      } else {
        EXPECT_LT(imu + scans + poses, static_cast<size_t>(kNumImu + 20 + 40)) << context;
        EXPECT_EQ(stats.recovery.damaged_records, 1) << context;  // the cut-off chunk
        if (imu > 0) ++partial;
      }
    }
    EXPECT_GT(partial, 3) << config::EnumToString(compression);
  }
}

// A recorder killed mid-chunk: index_pos = 0, and the open chunk's header
// still has rosbag's placeholder sizes (0, 0); the file ends inside it.
TEST(BagRecoveryTest, UnterminatedChunkOfAKilledRecorderIsRead) {
  TempDir dir;
  const std::string path = dir.File("full.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), kNumImu, kPointsPerScan);
  std::string file = ReadBytes(path);
  const MessageEnds ends = FindMessageEnds(file);
  const uint64_t index_pos = IndexPos(file);
  ClearIndexPos(&file);
  // The last chunk header: fields "compression=none", "op=\x05", "size=" + u32,
  // then the u32 data length.
  const size_t compression_at = file.rfind("compression=none");
  ASSERT_NE(compression_at, std::string::npos);
  ASSERT_GT(compression_at, file.find("compression=none"));  // several chunks
  const size_t size_at = file.find("size=", compression_at) + 5;
  const size_t data_length_at = size_at + 4;
  uint32_t chunk_bytes = 0;
  for (int i = 3; i >= 0; --i) {
    chunk_bytes = (chunk_bytes << 8) | static_cast<uint8_t>(file[data_length_at + i]);
  }
  const size_t chunk_end = data_length_at + 4 + chunk_bytes;
  for (size_t i = 0; i < 4; ++i) file[size_at + i] = file[data_length_at + i] = '\0';
  ASSERT_LE(chunk_end, index_pos);

  const size_t chunk_data = data_length_at + 4;
  for (size_t cut : {chunk_data + 1000, chunk_data + chunk_bytes / 2, chunk_end - 3, chunk_end,
                     static_cast<size_t>(index_pos)}) {
    const std::string context = "cut at " + std::to_string(cut);
    const std::string cut_path = dir.File("active.bag");
    WriteBytes(cut_path, file.substr(0, cut));
    std::vector<BagRecord> records;
    ReadStats stats;
    const Status status = ReadAll(cut_path, BagReaderOptions(), &records, &stats);
    ASSERT_TRUE(status.ok()) << context << ": " << status.message();
    ExpectPrefixes(records, CountBefore(ends.imu, cut), CountBefore(ends.scans, cut),
                   CountBefore(ends.poses, cut), context);
    EXPECT_TRUE(stats.recovery.recovered);
    EXPECT_NE(stats.recovery.reason.find("not indexed"), std::string::npos)
        << stats.recovery.reason;
    EXPECT_EQ(stats.recovery.damaged_records, cut < chunk_end ? 1 : 0)
        << context << ": " << stats.recovery.Summary();
  }
}

// Bytes overwritten in unindexed bags (so the recovery scan reads them):
// reading ends in Ok or an error Status, never a crash or overrun.
TEST(BagRecoveryTest, CorruptUnindexedBagsNeverCrash) {
  TempDir dir;
  for (BagCompression compression :
       {BagCompression::kNone, BagCompression::kLz4, BagCompression::kBz2}) {
    const std::string path = dir.File("full.bag");
    BagWriterOptions options;
    options.compression = compression;
    testing::WriteSimpleBag(path, options, 60, 50);
    std::string original = ReadBytes(path);
    ClearIndexPos(&original);
    const size_t stride = std::max<size_t>(1, original.size() / 150);
    int ok = 0;
    for (size_t at = 4096; at + 16 <= original.size(); at += stride) {
      const char fill = (at / stride) % 2 == 0 ? '\xff' : '\x00';
      std::string bytes = original;
      for (size_t i = 0; i < 16; ++i) bytes[at + i] = fill;
      const std::string corrupt = dir.File("corrupt.bag");
      WriteBytes(corrupt, bytes.substr(0, bytes.size() - (at / stride) % 7 * 13));
      std::vector<BagRecord> records;
      BagReaderOptions read_options;
      read_options.skip_malformed_messages = (at / stride) % 3 == 0;
      const Status status = ReadAll(corrupt, read_options, &records);
      if (status.ok()) {
        ++ok;
      } else {
        EXPECT_NE(status.message().find(corrupt), std::string::npos) << status.message();
      }
      BagInfo info;
      static_cast<void>(ReadBagInfo(corrupt, &info));
    }
    EXPECT_GT(ok, 0);
  }
}

}  // namespace
}  // namespace swarmlio::io
