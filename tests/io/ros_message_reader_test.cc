#include "src/io/ros_message_reader.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace swarmlio::io::internal {
namespace {

TEST(RosMessageReaderTest, ReadsLittleEndianScalars) {
  const std::vector<uint8_t> bytes = {0x01, 0x78, 0x56, 0x34, 0x12, 0x08, 0x07, 0x06, 0x05,
                                      0x04, 0x03, 0x02, 0x01, 0x00, 0x00, 0x80, 0x3f};
  RosMessageReader reader(bytes.data(), bytes.size());
  uint8_t u8 = 0;
  uint32_t u32 = 0;
  uint64_t u64 = 0;
  float f32 = 0.f;
  ASSERT_TRUE(reader.ReadU8("a", &u8).ok());
  ASSERT_TRUE(reader.ReadU32("b", &u32).ok());
  ASSERT_TRUE(reader.ReadU64("c", &u64).ok());
  ASSERT_TRUE(reader.ReadF32("d", &f32).ok());
  EXPECT_EQ(u8, 1);
  EXPECT_EQ(u32, 0x12345678u);
  EXPECT_EQ(u64, 0x0102030405060708ull);
  EXPECT_EQ(f32, 1.0f);
  EXPECT_EQ(reader.remaining(), 0u);
  EXPECT_TRUE(reader.ExpectEnd("m").ok());
}

TEST(RosMessageReaderTest, TruncatedReadIsDataLossNamingTheField) {
  const std::vector<uint8_t> bytes = {1, 2, 3};
  RosMessageReader reader(bytes.data(), bytes.size());
  uint32_t value = 0;
  const Status status = reader.ReadU32("header.seq", &value);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_NE(status.message().find("header.seq"), std::string::npos);
  EXPECT_EQ(reader.position(), 0u);
}

TEST(RosMessageReaderTest, LyingArrayLengthIsRejectedBeforeAllocation) {
  // Length 0xFFFFFFFF followed by 4 bytes.
  const std::vector<uint8_t> bytes = {0xff, 0xff, 0xff, 0xff, 1, 2, 3, 4};
  RosMessageReader reader(bytes.data(), bytes.size());
  std::string text;
  EXPECT_EQ(reader.ReadString("frame_id", &text).code(), Status::Code::kDataLoss);
  RosMessageReader reader2(bytes.data(), bytes.size());
  uint32_t length = 0;
  EXPECT_FALSE(reader2.ReadArrayLength("points", 19, &length).ok());
  // 0 elements of any size is fine.
  const std::vector<uint8_t> empty = {0, 0, 0, 0};
  RosMessageReader reader3(empty.data(), empty.size());
  EXPECT_TRUE(reader3.ReadArrayLength("points", 19, &length).ok());
  EXPECT_EQ(length, 0u);
}

TEST(RosMessageReaderTest, ArrayLengthOverflowIsRejected) {
  // 0x40000000 elements * 8 bytes overflows 32 bits; must still be rejected.
  std::vector<uint8_t> bytes = {0x00, 0x00, 0x00, 0x40};
  bytes.resize(64, 0);
  RosMessageReader reader(bytes.data(), bytes.size());
  uint32_t length = 0;
  EXPECT_FALSE(reader.ReadArrayLength("data", 8, &length).ok());
}

TEST(RosMessageReaderTest, TrailingBytesAreReported) {
  const std::vector<uint8_t> bytes = {1, 2};
  RosMessageReader reader(bytes.data(), bytes.size());
  uint8_t value = 0;
  ASSERT_TRUE(reader.ReadU8("a", &value).ok());
  EXPECT_EQ(reader.ExpectEnd("m").code(), Status::Code::kDataLoss);
}

}  // namespace
}  // namespace swarmlio::io::internal
