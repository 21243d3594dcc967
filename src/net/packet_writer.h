// Appends little-endian integers and IEEE floats to a byte buffer (no padding):
// the encoding side of PacketReader (packet_reader.h).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

namespace swarmlio::net::internal {

class PacketWriter {
 public:
  explicit PacketWriter(std::vector<uint8_t>* out) : out_(out) {}

  void U8(uint8_t value) { out_->push_back(value); }
  void U16(uint16_t value) { PutLittleEndian(value, 2); }
  void I16(int16_t value) { PutLittleEndian(static_cast<uint16_t>(value), 2); }
  void U32(uint32_t value) { PutLittleEndian(value, 4); }
  /// The low 48 bits of `value`, two's complement (the caller checked the range).
  void I48(int64_t value) { PutLittleEndian(static_cast<uint64_t>(value), 6); }
  void I64(int64_t value) { PutLittleEndian(static_cast<uint64_t>(value), 8); }
  /// Rounds to the nearest float32 (the caller checked it is finite there).
  void F32(double value) {
    const float f = static_cast<float>(value);
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof(bits));
    PutLittleEndian(bits, 4);
  }

 private:
  template <class UInt>
  void PutLittleEndian(UInt value, int bytes) {
    for (int i = 0; i < bytes; ++i) out_->push_back(static_cast<uint8_t>(value >> (8 * i)));
  }

  std::vector<uint8_t>* out_;
};

}  // namespace swarmlio::net::internal
