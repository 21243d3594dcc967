// Bounds-checked reader of serialized ROS message bytes (little endian):
// ROS1 serialization, or ROS 2 CDR (XCDR1 little endian, after Begin(kCdr)
// has checked the 4-byte encapsulation header: every primitive is then
// aligned to its size relative to the byte after that header, strings carry
// their NUL in the length, and up to 3 trailing padding bytes are allowed).
//
// Every read checks the remaining byte count first; an array or string length
// read from the wire is checked against the remaining bytes before anything
// is allocated, so a corrupt length can neither overrun the buffer nor trigger
// a huge allocation. Errors are DataLoss Status values naming the field.
// Floats are returned as read, NaN included: a scan's NaN points are dropped
// one by one by the record checks (docs/bag_format.md), not the whole
// message. Also parses bag record headers (u32-length-prefixed fields, the
// same encoding). Swarm packets have their own reader, which also checks
// values: net's PacketReader (src/net/packet_reader.h says why there are two).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// How a message is serialized.
enum class WireEncoding { kRos1, kCdr };

/// Loads an unsigned little-endian integer from `bytes` (no alignment needed).
template <class UInt>
UInt LoadLittleEndian(const uint8_t* bytes) {
  UInt value = 0;
  for (size_t i = 0; i < sizeof(UInt); ++i) {
    value = static_cast<UInt>(value | (static_cast<UInt>(bytes[i]) << (8 * i)));
  }
  return value;
}

inline float LoadFloat32(const uint8_t* bytes) {
  const uint32_t bits = LoadLittleEndian<uint32_t>(bytes);
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

inline double LoadFloat64(const uint8_t* bytes) {
  const uint64_t bits = LoadLittleEndian<uint64_t>(bytes);
  double value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

class RosMessageReader {
 public:
  RosMessageReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  size_t position() const { return position_; }
  size_t remaining() const { return size_ - position_; }
  WireEncoding encoding() const { return encoding_; }

  /// Selects the encoding; for kCdr reads and checks the encapsulation
  /// header (CDR_LE: 00 01, options ignored). Call once, before any read.
  Status Begin(WireEncoding encoding) {
    encoding_ = encoding;
    if (encoding != WireEncoding::kCdr) return Status::Ok();
    SWARMLIO_RETURN_IF_ERROR(Require("CDR encapsulation header", 4));
    const uint8_t kind_high = data_[position_];
    const uint8_t kind_low = data_[position_ + 1];
    if (kind_high != 0x00 || kind_low != 0x01) {
      return Status::DataLoss("CDR encapsulation kind " + std::to_string(kind_high) + "," +
                              std::to_string(kind_low) + " is not little-endian plain CDR (0,1)");
    }
    position_ += 4;
    origin_ = position_;
    return Status::Ok();
  }

  /// CDR: skips the padding up to a multiple of `alignment` bytes (from the
  /// byte after the encapsulation header). ROS1: no-op.
  Status Align(const char* field, size_t alignment) {
    if (encoding_ != WireEncoding::kCdr) return Status::Ok();
    const size_t misaligned = (position_ - origin_) % alignment;
    if (misaligned == 0) return Status::Ok();
    SWARMLIO_RETURN_IF_ERROR(Require(field, alignment - misaligned));
    position_ += alignment - misaligned;
    return Status::Ok();
  }

  Status ReadU8(const char* field, uint8_t* value) {
    SWARMLIO_RETURN_IF_ERROR(Require(field, 1));
    *value = data_[position_++];
    return Status::Ok();
  }
  Status ReadU16(const char* field, uint16_t* value) {
    SWARMLIO_RETURN_IF_ERROR(Align(field, 2));
    SWARMLIO_RETURN_IF_ERROR(Require(field, 2));
    *value = LoadLittleEndian<uint16_t>(data_ + position_);
    position_ += 2;
    return Status::Ok();
  }
  Status ReadU32(const char* field, uint32_t* value) {
    SWARMLIO_RETURN_IF_ERROR(Align(field, 4));
    SWARMLIO_RETURN_IF_ERROR(Require(field, 4));
    *value = LoadLittleEndian<uint32_t>(data_ + position_);
    position_ += 4;
    return Status::Ok();
  }
  Status ReadU64(const char* field, uint64_t* value) {
    SWARMLIO_RETURN_IF_ERROR(Align(field, 8));
    SWARMLIO_RETURN_IF_ERROR(Require(field, 8));
    *value = LoadLittleEndian<uint64_t>(data_ + position_);
    position_ += 8;
    return Status::Ok();
  }
  Status ReadF32(const char* field, float* value) {
    SWARMLIO_RETURN_IF_ERROR(Align(field, 4));
    SWARMLIO_RETURN_IF_ERROR(Require(field, 4));
    *value = LoadFloat32(data_ + position_);
    position_ += 4;
    return Status::Ok();
  }
  Status ReadF64(const char* field, double* value) {
    SWARMLIO_RETURN_IF_ERROR(Align(field, 8));
    SWARMLIO_RETURN_IF_ERROR(Require(field, 8));
    *value = LoadFloat64(data_ + position_);
    position_ += 8;
    return Status::Ok();
  }

  /// Skips `count` float64 values (a fixed-size array), aligned first.
  Status SkipF64s(const char* field, size_t count) {
    SWARMLIO_RETURN_IF_ERROR(Align(field, 8));
    const uint8_t* unused = nullptr;
    return ReadBytes(field, count * 8, &unused);
  }

  /// Returns a pointer to the next `count` bytes and skips them (no
  /// alignment: bytes, or what the caller aligned).
  Status ReadBytes(const char* field, size_t count, const uint8_t** bytes) {
    SWARMLIO_RETURN_IF_ERROR(Require(field, count));
    *bytes = data_ + position_;
    position_ += count;
    return Status::Ok();
  }

  /// Reads a uint32 length prefix and checks that `length * element_bytes`
  /// bytes remain (element_bytes = the smallest possible element size).
  Status ReadArrayLength(const char* field, size_t element_bytes, uint32_t* length) {
    uint32_t n = 0;
    SWARMLIO_RETURN_IF_ERROR(ReadU32(field, &n));
    const uint64_t needed = static_cast<uint64_t>(n) * static_cast<uint64_t>(element_bytes);
    if (needed > remaining()) {
      return Status::DataLoss(std::string("field '") + field + "' claims " + std::to_string(n) +
                              " elements (" + std::to_string(needed) + " bytes) but only " +
                              std::to_string(remaining()) + " bytes remain at offset " +
                              std::to_string(position_));
    }
    *length = n;
    return Status::Ok();
  }

  /// Reads a string: uint32 length + bytes (CDR: the length counts a
  /// terminating NUL, which must be there and is dropped).
  Status ReadString(const char* field, std::string* value) {
    uint32_t n = 0;
    SWARMLIO_RETURN_IF_ERROR(ReadArrayLength(field, 1, &n));
    size_t chars = n;
    if (encoding_ == WireEncoding::kCdr && n > 0) {
      if (data_[position_ + n - 1] != 0) {
        return Status::DataLoss(std::string("CDR string '") + field +
                                "' lacks its terminating NUL at offset " +
                                std::to_string(position_ + n - 1));
      }
      chars = n - 1;
    }
    value->assign(reinterpret_cast<const char*>(data_ + position_), chars);
    position_ += n;
    return Status::Ok();
  }

  /// Fails if bytes remain (the message is longer than its type says); CDR
  /// allows up to 3 bytes of final padding.
  Status ExpectEnd(const char* message_type) const {
    if (remaining() == 0) return Status::Ok();
    if (encoding_ == WireEncoding::kCdr && remaining() < 4) return Status::Ok();
    return Status::DataLoss(std::string(message_type) + ": " + std::to_string(remaining()) +
                            " unexpected trailing bytes after offset " + std::to_string(position_));
  }

 private:
  Status Require(const char* field, size_t count) const {
    if (count <= remaining()) return Status::Ok();
    return Status::DataLoss(std::string("message truncated reading field '") + field + "': need " +
                            std::to_string(count) + " bytes at offset " +
                            std::to_string(position_) + ", " + std::to_string(remaining()) +
                            " remain");
  }

  const uint8_t* data_;
  size_t size_;
  size_t position_ = 0;
  size_t origin_ = 0;  // CDR alignment origin
  WireEncoding encoding_ = WireEncoding::kRos1;
};

}  // namespace swarmlio::io::internal
