// rosbag2 storage: .db3 files (SQLite3, made here with libsqlite3 as
// rosbag2's sqlite3 plugin lays them out) and rosbag2 folders (metadata.yaml
// naming .db3 or .mcap files, a split recording read as one log) read back
// like the same records in a ROS1 bag; corrupt .db3 files are errors, never
// crashes.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "src/io/mcap_scan.h"
#include "swarmlio/io/bag_info.h"
#include "tests/io/bag_test_util.h"

namespace swarmlio::io {
namespace {

using testing::ReadAll;
using testing::TempDir;

bool Exec(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  const bool ok = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) == SQLITE_OK;
  EXPECT_TRUE(ok) << sql << ": " << (error != nullptr ? error : "");
  sqlite3_free(error);
  return ok;
}

// Copies the messages of `mcap` with index in [begin, end) (file order) into
// a new rosbag2 .db3 file: topics keep their names, ROS 2 types and "cdr".
void McapToDb3(const std::string& mcap,
               const std::string& db3,
               size_t begin = 0,
               size_t end = SIZE_MAX) {
  internal::McapFile file;
  ASSERT_TRUE(internal::ScanMcapFile(mcap, false, &file).ok());
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db3.c_str(), &db), SQLITE_OK);
  Exec(db,
       "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
       "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
       "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
       "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
       "CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
  for (size_t c = 0; c < file.channels.size(); ++c) {
    Exec(db, "INSERT INTO topics VALUES (" + std::to_string(c + 1) + ", '" +
                 file.channels[c].topic + "', '" + file.channels[c].schema_name + "', 'cdr', '')");
  }
  sqlite3_stmt* insert = nullptr;
  ASSERT_EQ(
      sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?,?,?)", -1,
                         &insert, nullptr),
      SQLITE_OK);
  internal::McapChunkCache cache(&file);
  internal::McapMessageReader reader(&file, &cache);
  Exec(db, "BEGIN");
  for (size_t i = begin; i < std::min(end, file.messages.size()); ++i) {
    const internal::McapMessage& m = file.messages[i];
    const uint8_t* data = nullptr;
    ASSERT_TRUE(reader.Read(m, &data).ok());
    sqlite3_bind_int64(insert, 1, m.channel + 1);
    sqlite3_bind_int64(insert, 2, m.log_time_ns);
    sqlite3_bind_blob(insert, 3, data, static_cast<int>(m.size), SQLITE_TRANSIENT);
    ASSERT_EQ(sqlite3_step(insert), SQLITE_DONE);
    sqlite3_reset(insert);
  }
  Exec(db, "COMMIT");
  sqlite3_finalize(insert);
  sqlite3_close(db);
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

std::string Metadata(const std::string& storage, const std::vector<std::string>& files) {
  std::string text =
      "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: " + storage +
      "\n  relative_file_paths:\n";
  for (const std::string& f : files) text += "    - " + f + "\n";
  return text;
}

class Rosbag2Test : public ::testing::Test {
 protected:
  void SetUp() override {
    BagWriterOptions options;
    options.lidar_format = LidarMessageFormat::kPointCloud2;
    testing::WriteSimpleBag(dir_.File("run.bag"), options, 200, 30);
    testing::WriteSimpleBag(dir_.File("run.mcap"), options, 200, 30);
    ASSERT_TRUE(ReadAll(dir_.File("run.bag"), BagReaderOptions(), &expected_).ok());
    ASSERT_EQ(expected_.size(), 200u + 10u + 20u);
  }

  TempDir dir_;
  std::vector<BagRecord> expected_;
};

TEST_F(Rosbag2Test, Db3FileReadsLikeTheRos1Bag) {
  McapToDb3(dir_.File("run.mcap"), dir_.File("run.db3"));
  std::vector<BagRecord> records;
  const Status status = ReadAll(dir_.File("run.db3"), BagReaderOptions(), &records);
  ASSERT_TRUE(status.ok()) << status.message();
  testing::ExpectSameRecords(records, expected_);
  BagInfo info;
  ASSERT_TRUE(ReadBagInfo(dir_.File("run.db3"), &info).ok());
  EXPECT_EQ(info.format, "db3");
  EXPECT_EQ(info.message_count, 230);
  ASSERT_EQ(info.topics.size(), 3u);
  EXPECT_EQ(info.topics[2].datatype, "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(info.topics[2].encoding, "cdr");
  EXPECT_EQ(info.topics[2].message_count, 10);
}

TEST_F(Rosbag2Test, SplitFolderReadsAsOneLog) {
  const std::string folder = dir_.File("split");
  std::filesystem::create_directory(folder);
  McapToDb3(dir_.File("run.mcap"), folder + "/split_0.db3", 0, 100);
  McapToDb3(dir_.File("run.mcap"), folder + "/split_1.db3", 100);
  WriteText(folder + "/metadata.yaml", Metadata("sqlite3", {"split_0.db3", "split_1.db3"}));
  std::vector<BagRecord> records;
  const Status status = ReadAll(folder, BagReaderOptions(), &records);
  ASSERT_TRUE(status.ok()) << status.message();
  testing::ExpectSameRecords(records, expected_);
  BagInfo info;
  ASSERT_TRUE(ReadBagInfo(folder, &info).ok());
  EXPECT_EQ(info.format, "rosbag2");
  EXPECT_EQ(info.message_count, 230);
  EXPECT_EQ(info.topics[1].message_count, 200);
  // ROS 2 Foxy's metadata.yaml prefixed the paths with the folder's name.
  WriteText(folder + "/metadata.yaml",
            Metadata("sqlite3", {"split/split_0.db3", "split/split_1.db3"}));
  ASSERT_TRUE(ReadAll(folder, BagReaderOptions(), &records).ok());
  testing::ExpectSameRecords(records, expected_);
  // Without metadata.yaml: the .db3 files in name order.
  std::filesystem::remove(folder + "/metadata.yaml");
  ASSERT_TRUE(ReadAll(folder, BagReaderOptions(), &records).ok());
  testing::ExpectSameRecords(records, expected_);
}

TEST_F(Rosbag2Test, McapFolderAndBadMetadata) {
  const std::string folder = dir_.File("mcap_folder");
  std::filesystem::create_directory(folder);
  std::filesystem::copy_file(dir_.File("run.mcap"), folder + "/mcap_folder_0.mcap");
  WriteText(folder + "/metadata.yaml", Metadata("mcap", {"mcap_folder_0.mcap"}));
  std::vector<BagRecord> records;
  ASSERT_TRUE(ReadAll(folder, BagReaderOptions(), &records).ok());
  testing::ExpectSameRecords(records, expected_);
  WriteText(folder + "/metadata.yaml", Metadata("mcap", {"missing.mcap"}));
  Status status = ReadAll(folder, BagReaderOptions(), &records);
  EXPECT_EQ(status.code(), Status::Code::kNotFound) << status.message();
  WriteText(folder + "/metadata.yaml", "rosbag2_bagfile_information: [unclosed\n");
  status = ReadAll(folder, BagReaderOptions(), &records);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_NE(status.message().find(folder), std::string::npos) << status.message();
  const std::string empty = dir_.File("empty_folder");
  std::filesystem::create_directory(empty);
  EXPECT_EQ(ReadAll(empty, BagReaderOptions(), &records).code(), Status::Code::kNotFound);
}

// Bytes overwritten at ~100 places of a .db3 file, some files cut short:
// reading ends in Ok or an error naming the file, never a crash.
TEST_F(Rosbag2Test, CorruptDb3FilesNeverCrash) {
  McapToDb3(dir_.File("run.mcap"), dir_.File("run.db3"));
  std::ifstream in(dir_.File("run.db3"), std::ios::binary);
  const std::string original((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  const size_t stride = std::max<size_t>(1, original.size() / 100);
  int errors = 0;
  for (size_t at = 0; at + 16 <= original.size(); at += stride) {
    std::string bytes = original;
    for (size_t i = 0; i < 16; ++i) bytes[at + i] = (at / stride) % 2 == 0 ? '\xff' : '\x00';
    bytes.resize(bytes.size() - (at / stride) % 4 * 1000);
    const std::string corrupt = dir_.File("corrupt.db3");
    {
      std::ofstream out(corrupt, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    std::vector<BagRecord> records;
    BagReaderOptions options;
    options.skip_malformed_messages = (at / stride) % 3 == 0;
    const Status status = ReadAll(corrupt, options, &records);
    if (!status.ok()) {
      ++errors;
      EXPECT_NE(status.message().find(corrupt), std::string::npos) << status.message();
    }
    BagInfo info;
    static_cast<void>(ReadBagInfo(corrupt, &info));
  }
  EXPECT_GT(errors, 0);
}

}  // namespace
}  // namespace swarmlio::io
