// Constants of the MCAP container format (https://mcap.dev/spec), shared by
// the MCAP scan (mcap_scan.h) and writer (mcap_writer.h). Every record is
// opcode (u8), content length (u64), content; integers little endian,
// strings and byte arrays u32-length-prefixed, maps u32-byte-length-prefixed.
#pragma once

#include <cstddef>
#include <cstdint>

namespace swarmlio::io::internal {

inline constexpr uint8_t kMcapMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
inline constexpr size_t kMcapMagicBytes = sizeof(kMcapMagic);
// Opcode (1) + content length (8).
inline constexpr uint64_t kMcapRecordPrefixBytes = 9;

enum McapOp : uint8_t {
  kMcapHeader = 0x01,
  kMcapFooter = 0x02,
  kMcapSchema = 0x03,
  kMcapChannel = 0x04,
  kMcapMessage = 0x05,
  kMcapChunk = 0x06,
  kMcapMessageIndex = 0x07,
  kMcapChunkIndex = 0x08,
  kMcapAttachment = 0x09,
  kMcapAttachmentIndex = 0x0A,
  kMcapStatistics = 0x0B,
  kMcapMetadata = 0x0C,
  kMcapMetadataIndex = 0x0D,
  kMcapSummaryOffset = 0x0E,
  kMcapDataEnd = 0x0F,
};

// Message record content before the data: channel_id u16, sequence u32,
// log_time u64, publish_time u64.
inline constexpr uint64_t kMcapMessageHeaderBytes = 22;

/// True when `bytes` (at least kMcapMagicBytes) start with the MCAP magic.
inline bool IsMcapMagic(const uint8_t* bytes) {
  for (size_t i = 0; i < kMcapMagicBytes; ++i) {
    if (bytes[i] != kMcapMagic[i]) return false;
  }
  return true;
}

}  // namespace swarmlio::io::internal
