// Sequential scan of an MCAP file's data section (https://mcap.dev/spec):
// Header, Schema, Channel, Message and Chunk records in file order (chunks
// are decompressed and their records walked; their uncompressed CRC is
// checked when non-zero), up to the DataEnd record, whose data-section CRC
// is checked when non-zero. The summary section is not needed and not read,
// so a file without one (a writer that died) or cut off anywhere still gives
// every complete record before the damage, as the ROS1 recovery does: the
// scan stops at the first cut-off or unreadable record, skips a chunk whose
// CRC fails or that does not decompress, and counts what it lost in
// BagRecoveryStats. Every length is checked against what remains of its
// record, chunk or file before anything is read or allocated.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "src/io/bag_records.h"
#include "swarmlio/common/status.h"
#include "swarmlio/io/read_stats.h"

namespace swarmlio::io::internal {

struct McapChannel {
  uint16_t id = 0;
  std::string topic;
  std::string message_encoding;  // "cdr", "ros1", ...
  std::string schema_name;       // "" when the channel has no schema
  std::string schema_encoding;   // "ros2msg", "ros1msg", ...
  std::map<std::string, std::string> metadata;
};

struct McapChunk {
  uint64_t records_offset = 0;  // file offset of the stored (compressed) records
  uint64_t records_bytes = 0;
  uint64_t uncompressed_bytes = 0;
  std::string compression;  // "", "zstd" or "lz4"
};

/// Where one complete message's data lies.
struct McapMessage {
  uint32_t channel = 0;  // index into McapFile::channels
  int64_t log_time_ns = 0;
  int64_t chunk = -1;   // index into McapFile::chunks; -1: data lies in the file
  uint64_t offset = 0;  // file offset (chunk -1) or offset in the decompressed chunk
  uint64_t size = 0;    // data bytes
};

struct McapFile {
  std::string path;
  std::string profile;  // the Header's profile ("ros2", "ros1", ...)
  std::vector<McapChannel> channels;
  std::vector<McapChunk> chunks;
  std::vector<McapMessage> messages;  // in file order
  BagRecoveryStats damage;            // recovered = true when anything was lost or unfinished
};

/// Scans the MCAP file at `path` (see the file comment). Without `recover`
/// any damage (cut-off record, bad CRC, missing DataEnd/footer) is DataLoss;
/// with it the damage is counted in file->damage. NotFound / IoError when
/// the file cannot be opened; DataLoss when it is not MCAP.
Status ScanMcapFile(const std::string& path, bool recover, McapFile* file);

/// Reads message bytes of a scanned file, keeping the last decompressed
/// chunk (the messages of one topic are read in nearly file order).
class McapMessageReader {
 public:
  /// `file` must outlive the reader.
  explicit McapMessageReader(const McapFile* file);

  /// Points *data at the message's bytes, valid until the next call.
  Status Read(const McapMessage& message, const uint8_t** data);

 private:
  const McapFile* file_;
  std::unique_ptr<BagFile> reader_;
  int64_t cached_chunk_ = -1;
  std::vector<uint8_t> stored_;
  std::vector<uint8_t> chunk_;
};

}  // namespace swarmlio::io::internal
