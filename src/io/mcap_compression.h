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

#include "src/io/byte_buffer.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// True for "", "zstd" and "lz4".
bool IsSupportedMcapCompression(const std::string& compression);

/// A chunk's records from its `size` stored bytes at `data`: without
/// compression ("") the stored bytes themselves (*records = data, once
/// `uncompressed_size` is checked to equal `size`), else decompressed into
/// exactly `uncompressed_size` bytes of *buffer (*records = buffer->data()).
/// DataLoss (with the reason) if they do not decompress to exactly that
/// size, or if the size is implausible for the stored bytes (a corrupt
/// field, refused before allocating).
Status McapChunkRecords(const std::string& compression,
                        const uint8_t* data,
                        size_t size,
                        uint64_t uncompressed_size,
                        ByteBuffer* buffer,
                        const uint8_t** records);

/// Compresses `size` bytes with `compression` ("" copies them).
Status CompressMcapChunk(const std::string& compression,
                         const uint8_t* data,
                         size_t size,
                         std::vector<uint8_t>* out);

}  // namespace swarmlio::io::internal
