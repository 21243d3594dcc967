// Chunk compression of MCAP files: "" (none), "zstd" (libzstd) and "lz4"
// (the LZ4 *frame* format, liblz4's lz4frame); the CRC-32 MCAP uses is in
// crc32.h. Decompression never trusts a size field: the output must be
// exactly the chunk's stated uncompressed size, which is sanity-checked
// against the stored size before anything is allocated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// True for "", "zstd" and "lz4".
bool IsSupportedMcapCompression(const std::string& compression);

/// Decompresses `size` stored bytes into exactly `uncompressed_size` bytes;
/// DataLoss (with the reason) if they do not, or if the size is implausible
/// for the stored bytes (a corrupt field, refused before allocating).
Status DecompressMcapChunk(const std::string& compression,
                           const uint8_t* data,
                           size_t size,
                           uint64_t uncompressed_size,
                           std::vector<uint8_t>* out);

/// Compresses `size` bytes with `compression` ("" copies them).
Status CompressMcapChunk(const std::string& compression,
                         const uint8_t* data,
                         size_t size,
                         std::vector<uint8_t>* out);

}  // namespace swarmlio::io::internal
