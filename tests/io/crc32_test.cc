// src/io/crc32.h (ISA-L) against zlib's crc32, the CRC MCAP files carry.
#include "src/io/crc32.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace swarmlio::io::internal {
namespace {

uint32_t ZlibCrc(const uint8_t* data, size_t size, uint32_t seed = 0) {
  return static_cast<uint32_t>(crc32_z(seed, data, size));
}

std::vector<uint8_t> RandomBytes(size_t size, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<uint8_t> bytes(size);
  for (uint8_t& b : bytes) b = static_cast<uint8_t>(random());
  return bytes;
}

TEST(Crc32Test, StandardCheckValueAndEmptyInput) {
  const std::string text = "123456789";
  EXPECT_EQ(Crc32(reinterpret_cast<const uint8_t*>(text.data()), text.size()), 0xCBF43926u);
  EXPECT_EQ(Crc32(nullptr, 0), 0u);
  EXPECT_EQ(Crc32(nullptr, 0, 0x12345678u), 0x12345678u);
}

// Every length up to 300 and some large ones, starting at every alignment:
// the vector code has head, body and tail paths.
TEST(Crc32Test, EqualsZlibForAnyLengthAndAlignment) {
  const std::vector<uint8_t> bytes = RandomBytes((1u << 20) + 64, 7);
  for (size_t start = 0; start < 16; ++start) {
    for (size_t size = 0; size <= 300; ++size) {
      ASSERT_EQ(Crc32(bytes.data() + start, size), ZlibCrc(bytes.data() + start, size))
          << "start " << start << " size " << size;
    }
    for (size_t size : {1023u, 4096u, 65537u, 1u << 20}) {
      ASSERT_EQ(Crc32(bytes.data() + start, size), ZlibCrc(bytes.data() + start, size))
          << "start " << start << " size " << size;
    }
  }
}

// A CRC continued piece by piece (as the data-section CRC is, record by
// record) equals the CRC of the whole, and equals zlib's continuation.
TEST(Crc32Test, IncrementalUseEqualsTheWhole) {
  const std::vector<uint8_t> bytes = RandomBytes(200000, 11);
  std::mt19937 random(3);
  const uint32_t whole = ZlibCrc(bytes.data(), bytes.size());
  uint32_t crc = 0;
  size_t at = 0;
  while (at < bytes.size()) {
    const size_t piece = std::min<size_t>(random() % 5000, bytes.size() - at);
    const uint32_t next = Crc32(bytes.data() + at, piece, crc);
    ASSERT_EQ(next, ZlibCrc(bytes.data() + at, piece, crc)) << "at " << at;
    crc = next;
    at += piece;
  }
  EXPECT_EQ(crc, whole);
}

TEST(Crc32Test, CombineJoinsTwoCrcs) {
  const std::vector<uint8_t> bytes = RandomBytes(300000, 5);
  for (size_t split : {0u, 1u, 9u, 4097u, 150000u, 299999u, 300000u}) {
    const uint32_t a = Crc32(bytes.data(), split);
    const uint32_t b = Crc32(bytes.data() + split, bytes.size() - split);
    EXPECT_EQ(Crc32Combine(a, b, bytes.size() - split), ZlibCrc(bytes.data(), bytes.size()))
        << "split " << split;
  }
}

}  // namespace
}  // namespace swarmlio::io::internal
