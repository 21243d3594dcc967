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
#include "src/io/byte_buffer.h"
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

/// The records of one chunk as read by McapChunkCache.
struct McapCachedChunk {
  int64_t chunk = -1;             // index into McapFile::chunks; -1 while being read
  const uint8_t* data = nullptr;  // the records: in `stored` if uncompressed, else `decompressed`
  uint64_t size = 0;
  ByteBuffer stored;
  ByteBuffer decompressed;
};

/// The chunks of a scanned file, each read from the file (and decompressed)
/// once for all the topic streams over it: they move through the file
/// together (the reader merges them by time), so the last few chunks are
/// kept. Not thread-safe: the streams of one source are read by one thread.
class McapChunkCache {
 public:
  /// `file` must outlive the cache.
  explicit McapChunkCache(const McapFile* file);

  /// Points *records at chunk `chunk`'s records (checked as by
  /// McapChunkRecords), which stay valid while *records is held. IoError if
  /// the file is shorter than at the scan.
  Status Get(int64_t chunk, std::shared_ptr<const McapCachedChunk>* records);

  /// Reads `size` bytes at file offset `offset` (an unchunked message).
  Status Read(uint64_t offset, uint64_t size, ByteBuffer* bytes);

 private:
  BagFile* File();  // opened at the first read

  const McapFile* file_;
  std::unique_ptr<BagFile> reader_;
  std::vector<std::shared_ptr<McapCachedChunk>> kept_;  // most recently used first
};

/// Reads message bytes of a scanned file for one topic stream: chunked
/// messages from the shared McapChunkCache, unchunked ones from the file.
class McapMessageReader {
 public:
  /// `file` and `cache` must outlive the reader.
  McapMessageReader(const McapFile* file, McapChunkCache* cache);

  /// Points *data at the message's bytes, valid until the next call.
  Status Read(const McapMessage& message, const uint8_t** data);

 private:
  const McapFile* file_;
  McapChunkCache* cache_;
  std::shared_ptr<const McapCachedChunk> chunk_;  // the last chunked message's
  ByteBuffer stored_;                             // the last unchunked message
};

}  // namespace swarmlio::io::internal
