// CRC-32 as MCAP (and gzip, zlib, PNG) uses it: ISO-HDLC, reflected
// polynomial 0xEDB88320, initial and final XOR 0xFFFFFFFF -- the value of
// zlib's crc32(). Computed with Intel ISA-L (Debian's libisal-dev), whose
// carry-less-multiply folding (chosen for the CPU at run time) is several
// times faster than zlib's on the megabyte chunks every MCAP read verifies
// (tools/bench/bench_crc32.cc).
#pragma once

#include <cstddef>
#include <cstdint>

namespace swarmlio::io::internal {

/// CRC-32 of `size` bytes, continuing from `seed`: 0 to start, or the CRC
/// of the bytes before them, so Crc32(b, nb, Crc32(a, na)) is the CRC of a
/// followed by b.
uint32_t Crc32(const uint8_t* data, size_t size, uint32_t seed = 0);

/// The CRC-32 of a followed by b, from crc_a = Crc32(a), crc_b = Crc32(b)
/// and b's length (zlib's crc32_combine: O(log size_b), without b's bytes;
/// z_off_t is 64 bits on the 64-bit targets we build for).
uint32_t Crc32Combine(uint32_t crc_a, uint32_t crc_b, uint64_t size_b);

}  // namespace swarmlio::io::internal
