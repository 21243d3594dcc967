#include "swarmlio/io/bag_info.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "swarmlio/io/bag_reader.h"

#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

TEST(BagInfoTest, ListsTopicsCountsAndTimes) {
  testing::TempDir dir;
  const std::string path = dir.File("info.bag");
  testing::WriteSimpleBag(path, BagWriterOptions(), 40);
  BagInfo info;
  const Status status = ReadBagInfo(path, &info);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(info.path, path);
  EXPECT_GT(info.file_size_bytes, 0u);
  EXPECT_EQ(info.message_count, 40 + 2 + 4);
  EXPECT_EQ(info.start_time_ns, 1000000000);
  // Last record: the scan at IMU 20, stored 100 ms after its stamp.
  EXPECT_EQ(info.end_time_ns, 1000000000 + 20 * 5000000 + 100000000);
  ASSERT_EQ(info.topics.size(), 3u);
  EXPECT_EQ(info.topics[0].topic, "/ground_truth/pose");
  EXPECT_EQ(info.topics[0].datatype, "geometry_msgs/PoseStamped");
  EXPECT_EQ(info.topics[0].message_count, 4);
  EXPECT_EQ(info.topics[1].topic, "/livox/imu");
  EXPECT_EQ(info.topics[1].message_count, 40);
  EXPECT_EQ(info.topics[1].first_time_ns, 1000000000);
  EXPECT_EQ(info.topics[1].last_time_ns, 1000000000 + 39 * 5000000);
  EXPECT_EQ(info.topics[2].topic, "/livox/lidar");
  EXPECT_EQ(info.topics[2].md5sum, "e4d6829bdfe657cb6c21a746c86b21a6");
  EXPECT_EQ(info.topics[2].message_count, 2);

  // The streaming reader reports the same bag time range.
  std::unique_ptr<BagReader> reader;
  ASSERT_TRUE(BagReader::Open(path, BagReaderOptions(), &reader).ok());
  EXPECT_EQ(reader->start_time_ns(), info.start_time_ns);
  EXPECT_EQ(reader->end_time_ns(), info.end_time_ns);
}

TEST(BagInfoTest, MissingFileIsNotFound) {
  testing::TempDir dir;
  BagInfo info;
  EXPECT_EQ(ReadBagInfo(dir.File("none.bag"), &info).code(), Status::Code::kNotFound);
}

}  // namespace
}  // namespace swarmlio::io
