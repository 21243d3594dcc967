// A growable byte buffer for bytes about to be overwritten (a file read, a
// decompression): unlike std::vector::resize, growing it neither zeroes the
// new bytes nor copies the old ones, and shrinking keeps the allocation for
// the next, similar-sized use (MCAP chunks are all about a megabyte).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

namespace swarmlio::io::internal {

class ByteBuffer {
 public:
  /// Makes the buffer `size` bytes long, uninitialised: the previous
  /// contents are lost. Never returns null (also for size 0).
  uint8_t* Resize(size_t size) {
    if (bytes_ == nullptr || size > capacity_) {
      capacity_ = size > 0 ? size : 1;
      bytes_.reset(new uint8_t[capacity_]);  // default-initialised: not zeroed
    }
    size_ = size;
    return bytes_.get();
  }

  uint8_t* data() { return bytes_.get(); }
  const uint8_t* data() const { return bytes_.get(); }
  size_t size() const { return size_; }

 private:
  std::unique_ptr<uint8_t[]> bytes_;
  size_t capacity_ = 0;
  size_t size_ = 0;
};

}  // namespace swarmlio::io::internal
