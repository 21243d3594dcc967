// Bounds-checked reader of little-endian swarm packet bytes.
//
// Every read checks the remaining byte count first and every float read
// rejects NaN and Inf, so a decoder built on it cannot overrun its buffer or
// let a non-finite value into the estimator. Errors are DataLoss Status values
// naming the field and the offset.
//
// Not merged with io's RosMessageReader (src/io/ros_message_reader.h), though
// both are bounds-checked little-endian readers: the two check different
// things. This one validates values (floats finite, Invalid() for the range
// checks of decoded codes, field names with an index) because a decoded packet
// goes straight into the estimator. ROS messages legitimately carry NaN (the
// invalid points of a PointCloud2, which the record checks drop one by one),
// so that reader returns values as read and checks length prefixes before
// allocating instead. Their error texts differ too ("truncated reading field"
// here, "message truncated reading field" there). One class would need a
// switch for both, and would offer the packet decoders unchecked float reads.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "src/net/half_float.h"
#include "swarmlio/common/status.h"

namespace swarmlio::net::internal {

class PacketReader {
 public:
  PacketReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  size_t position() const { return position_; }
  size_t remaining() const { return size_ - position_; }

  // `field` names the value in error messages, "field[index]" when index >= 0;
  // the text is built only on error (decoding is on the per-packet hot path).
  Status U8(const char* field, uint8_t* value) { return U8(field, -1, value); }
  Status U8(const char* field, int index, uint8_t* value) {
    SWARMLIO_RETURN_IF_ERROR(Require(field, index, 1));
    *value = data_[position_++];
    return Status::Ok();
  }
  Status U16(const char* field, uint16_t* value) { return Get(field, -1, 2, value); }
  Status U16(const char* field, int index, uint16_t* value) { return Get(field, index, 2, value); }
  Status U32(const char* field, uint32_t* value) { return Get(field, -1, 4, value); }
  Status I16(const char* field, int index, int16_t* value) {
    uint16_t bits = 0;
    SWARMLIO_RETURN_IF_ERROR(Get(field, index, 2, &bits));
    *value = static_cast<int16_t>(bits);
    return Status::Ok();
  }
  /// 48-bit two's complement, sign-extended.
  Status I48(const char* field, int64_t* value) {
    uint64_t bits = 0;
    SWARMLIO_RETURN_IF_ERROR(Get(field, -1, 6, &bits));
    if ((bits & (uint64_t{1} << 47)) != 0) bits |= ~((uint64_t{1} << 48) - 1);
    *value = static_cast<int64_t>(bits);
    return Status::Ok();
  }
  Status I64(const char* field, int64_t* value) {
    uint64_t bits = 0;
    SWARMLIO_RETURN_IF_ERROR(Get(field, -1, 8, &bits));
    *value = static_cast<int64_t>(bits);
    return Status::Ok();
  }
  /// A float32, widened exactly to double; NaN/Inf rejected.
  Status F32(const char* field, int index, double* value) {
    uint32_t bits = 0;
    SWARMLIO_RETURN_IF_ERROR(Get(field, index, 4, &bits));
    float f;
    std::memcpy(&f, &bits, sizeof(f));
    return Finite(field, index, static_cast<double>(f), value);
  }
  /// An IEEE binary16, widened exactly to double; NaN/Inf rejected.
  Status F16(const char* field, int index, double* value) {
    uint16_t bits = 0;
    SWARMLIO_RETURN_IF_ERROR(Get(field, index, 2, &bits));
    if (!IsFiniteHalf(bits)) return NotFinite(field, index);
    *value = DoubleFromHalf(bits);
    return Status::Ok();
  }

  /// Fails unless every byte was consumed.
  Status ExpectEnd(const char* what) const {
    if (remaining() == 0) return Status::Ok();
    return Status::DataLoss(std::string(what) + ": " + std::to_string(remaining()) +
                            " trailing bytes after offset " + std::to_string(position_));
  }

  /// DataLoss "field 'name[index]' <reason> (offset N)", N = the offset after
  /// the value just read: for range checks of decoded codes.
  Status Invalid(const char* field, int index, const std::string& reason) const {
    return Status::DataLoss("field '" + Name(field, index) + "' " + reason + " (offset " +
                            std::to_string(position_) + ")");
  }

 private:
  static std::string Name(const char* field, int index) {
    return index < 0 ? std::string(field) : std::string(field) + "[" + std::to_string(index) + "]";
  }

  template <class UInt>
  Status Get(const char* field, int index, size_t bytes, UInt* value) {
    SWARMLIO_RETURN_IF_ERROR(Require(field, index, bytes));
    UInt v = 0;
    for (size_t i = 0; i < bytes; ++i) {
      v = static_cast<UInt>(v | (static_cast<UInt>(data_[position_ + i]) << (8 * i)));
    }
    position_ += bytes;
    *value = v;
    return Status::Ok();
  }

  Status NotFinite(const char* field, int index) const {
    return Invalid(field, index, "is not finite");
  }

  Status Finite(const char* field, int index, double v, double* value) const {
    if (!std::isfinite(v)) return NotFinite(field, index);
    *value = v;
    return Status::Ok();
  }

  Status Require(const char* field, int index, size_t count) const {
    if (count <= remaining()) return Status::Ok();
    return Status::DataLoss("truncated reading field '" + Name(field, index) + "': need " +
                            std::to_string(count) + " bytes at offset " +
                            std::to_string(position_) + ", " + std::to_string(remaining()) +
                            " remain");
  }

  const uint8_t* data_;
  size_t size_;
  size_t position_ = 0;
};

}  // namespace swarmlio::net::internal
