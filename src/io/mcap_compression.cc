#include "src/io/mcap_compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <memory>

namespace swarmlio::io::internal {
namespace {

// Ratios above these mean a corrupt size field: LZ4 cannot exceed ~255:1,
// zstd reaches ~32000:1 only on constant data, never on sensor messages.
constexpr uint64_t kMaxLz4Ratio = 256;
constexpr uint64_t kMaxZstdRatio = 4096;
constexpr uint64_t kRatioSlackBytes = 1u << 16;
// No chunk we read may decompress to more than this.
constexpr uint64_t kMaxUncompressedBytes = uint64_t{1} << 32;

Status CheckSizes(const std::string& compression, size_t stored, uint64_t uncompressed) {
  if (compression.empty()) {
    if (uncompressed != stored) {
      return Status::DataLoss("uncompressed chunk holds " + std::to_string(stored) +
                              " bytes, its header says " + std::to_string(uncompressed));
    }
    return Status::Ok();
  }
  const uint64_t ratio = compression == "lz4" ? kMaxLz4Ratio : kMaxZstdRatio;
  if (uncompressed > kMaxUncompressedBytes ||
      uncompressed > static_cast<uint64_t>(stored) * ratio + kRatioSlackBytes) {
    return Status::DataLoss("implausible uncompressed size " + std::to_string(uncompressed) +
                            " for " + std::to_string(stored) + " " + compression + " bytes");
  }
  return Status::Ok();
}

Status DecompressZstd(const uint8_t* data, size_t size, ByteBuffer* out) {
  const size_t written = ZSTD_decompress(out->data(), out->size(), data, size);
  if (ZSTD_isError(written)) {
    return Status::DataLoss(std::string("zstd chunk does not decompress: ") +
                            ZSTD_getErrorName(written));
  }
  if (written != out->size()) {
    return Status::DataLoss("zstd chunk decompresses to " + std::to_string(written) +
                            " bytes, its header says " + std::to_string(out->size()));
  }
  return Status::Ok();
}

struct Lz4ContextDeleter {
  void operator()(LZ4F_dctx* context) const { LZ4F_freeDecompressionContext(context); }
};

Status DecompressLz4Frame(const uint8_t* data, size_t size, ByteBuffer* out) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    return Status::Internal("cannot create an LZ4 decompression context");
  }
  std::unique_ptr<LZ4F_dctx, Lz4ContextDeleter> context(raw);
  size_t in_pos = 0;
  size_t out_pos = 0;
  size_t hint = 1;
  while (hint != 0) {
    size_t in_bytes = size - in_pos;
    size_t out_bytes = out->size() - out_pos;
    hint = LZ4F_decompress(context.get(), out->data() + out_pos, &out_bytes, data + in_pos,
                           &in_bytes, nullptr);
    if (LZ4F_isError(hint)) {
      return Status::DataLoss(std::string("lz4 chunk does not decompress: ") +
                              LZ4F_getErrorName(hint));
    }
    in_pos += in_bytes;
    out_pos += out_bytes;
    if (hint != 0 && in_bytes == 0 && out_bytes == 0) {
      // No progress: the input ended inside the frame, or the output is full.
      return Status::DataLoss("lz4 frame is cut off or larger than the chunk's stated " +
                              std::to_string(out->size()) + " bytes");
    }
  }
  if (in_pos != size || out_pos != out->size()) {
    return Status::DataLoss("lz4 frame decompresses to " + std::to_string(out_pos) +
                            " bytes from " + std::to_string(in_pos) + " of " +
                            std::to_string(size) + " stored bytes; the chunk says " +
                            std::to_string(out->size()));
  }
  return Status::Ok();
}

}  // namespace

bool IsSupportedMcapCompression(const std::string& compression) {
  return compression.empty() || compression == "zstd" || compression == "lz4";
}

Status McapChunkRecords(const std::string& compression,
                        const uint8_t* data,
                        size_t size,
                        uint64_t uncompressed_size,
                        ByteBuffer* buffer,
                        const uint8_t** records) {
  if (!IsSupportedMcapCompression(compression)) {
    return Status::DataLoss("unsupported chunk compression '" + compression +
                            "' (supported: none, zstd, lz4)");
  }
  SWARMLIO_RETURN_IF_ERROR(CheckSizes(compression, size, uncompressed_size));
  if (compression == "zstd") {
    // The first frame's stated size must fit before anything is allocated
    // (a chunk may hold several frames, so it may be smaller).
    const unsigned long long frame_size = ZSTD_getFrameContentSize(data, size);
    if (frame_size != ZSTD_CONTENTSIZE_UNKNOWN &&
        (frame_size == ZSTD_CONTENTSIZE_ERROR || frame_size > uncompressed_size)) {
      return Status::DataLoss("zstd frame holds " +
                              (frame_size == ZSTD_CONTENTSIZE_ERROR
                                   ? std::string("no valid header")
                                   : std::to_string(frame_size) + " bytes") +
                              ", the chunk says " + std::to_string(uncompressed_size));
    }
  }
  if (compression.empty()) {
    *records = data;  // read in place
    return Status::Ok();
  }
  // Every byte is written by the decompressor (or the size check fails).
  buffer->Resize(static_cast<size_t>(uncompressed_size));
  SWARMLIO_RETURN_IF_ERROR(compression == "zstd" ? DecompressZstd(data, size, buffer)
                                                 : DecompressLz4Frame(data, size, buffer));
  *records = buffer->data();
  return Status::Ok();
}

Status CompressMcapChunk(const std::string& compression,
                         const uint8_t* data,
                         size_t size,
                         std::vector<uint8_t>* out) {
  if (compression.empty()) {
    out->assign(data, data + size);
    return Status::Ok();
  }
  if (compression == "zstd") {
    out->resize(ZSTD_compressBound(size));
    const size_t written = ZSTD_compress(out->data(), out->size(), data, size, 3);
    if (ZSTD_isError(written)) {
      return Status::Internal(std::string("zstd compression failed: ") +
                              ZSTD_getErrorName(written));
    }
    out->resize(written);
    return Status::Ok();
  }
  if (compression == "lz4") {
    LZ4F_preferences_t preferences = LZ4F_INIT_PREFERENCES;
    preferences.frameInfo.contentSize = size;
    out->resize(LZ4F_compressFrameBound(size, &preferences));
    const size_t written = LZ4F_compressFrame(out->data(), out->size(), data, size, &preferences);
    if (LZ4F_isError(written)) {
      return Status::Internal(std::string("lz4 compression failed: ") + LZ4F_getErrorName(written));
    }
    out->resize(written);
    return Status::Ok();
  }
  return Status::InvalidArgument("unsupported chunk compression '" + compression + "'");
}

}  // namespace swarmlio::io::internal
