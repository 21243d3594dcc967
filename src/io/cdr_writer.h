// Builds ROS 2 CDR message bytes (XCDR1 little endian): the 4-byte
// encapsulation header 00 01 00 00, then each primitive aligned to its size
// relative to the byte after that header, strings as uint32 length (with
// the NUL) + bytes + NUL, sequences as uint32 count + elements. The
// counterpart of RosMessageReader's kCdr mode.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace swarmlio::io::internal {

class CdrWriter {
 public:
  explicit CdrWriter(std::vector<uint8_t>* out) : out_(out) {
    out_->assign({0x00, 0x01, 0x00, 0x00});
  }

  void Align(size_t alignment) {
    const size_t misaligned = (out_->size() - kOrigin) % alignment;
    if (misaligned != 0) out_->insert(out_->end(), alignment - misaligned, 0);
  }
  void U8(uint8_t value) { out_->push_back(value); }
  void U32(uint32_t value) { Put(value); }
  void I32(int32_t value) { Put(value); }
  void U64(uint64_t value) { Put(value); }
  void F32(float value) { Put(value); }
  void F64(double value) { Put(value); }
  void String(const std::string& value) {
    U32(static_cast<uint32_t>(value.size() + 1));
    out_->insert(out_->end(), value.begin(), value.end());
    out_->push_back(0);
  }
  void Bytes(const uint8_t* data, size_t size) { out_->insert(out_->end(), data, data + size); }

 private:
  static constexpr size_t kOrigin = 4;

  template <class T>
  void Put(T value) {
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "little-endian host required");
    Align(sizeof(T));
    uint8_t bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out_->insert(out_->end(), bytes, bytes + sizeof(T));
  }

  std::vector<uint8_t>* out_;
};

}  // namespace swarmlio::io::internal
