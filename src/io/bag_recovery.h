// Recovery of damaged ROS1 bags (format 2.0): a bag that is not indexed (the
// recorder died before closing it: index_pos = 0, the last chunk's header
// still has its placeholder sizes) or whose index is cut off (the file was
// truncated). Its records are scanned in file order, as `rosbag reindex`
// does, with every length checked against the file size:
//   - chunk records: uncompressed ones are walked in place (an unterminated
//     or cut-off chunk up to its last complete record), LZ4/BZ2 ones are
//     decompressed (an unterminated or cut-off compressed chunk is lost);
//   - connection records (inside chunks, and in the index section) give
//     topic, datatype and MD5 per connection id;
//   - message data records give connection id, bag time and data location.
// The scan stops at the first record that is cut off or unreadable; what
// could not be read is counted in BagRecoveryStats. A compressed chunk that
// does not decompress is skipped (counted) and the scan goes on after it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "src/io/bag_records.h"
#include "swarmlio/common/status.h"
#include "swarmlio/io/read_stats.h"

namespace swarmlio::io::internal {

struct RecoveredConnection {
  uint32_t id = 0;
  std::string topic;
  std::string datatype;
  std::string md5sum;
};

struct RecoveredChunk {
  uint64_t data_offset = 0;  // file offset of the stored (compressed) bytes
  uint32_t stored_bytes = 0;
  uint32_t uncompressed_bytes = 0;
  std::string compression;  // "lz4" or "bz2" (uncompressed chunks are read in place)
};

/// Where one complete message record's data lies.
struct RecoveredMessage {
  uint32_t connection = 0;  // index into RecoveredBag::connections
  int64_t time_ns = 0;      // bag (receive) time
  int64_t chunk = -1;       // index into RecoveredBag::chunks; -1: data lies in the file
  uint64_t offset = 0;      // file offset (chunk -1) or offset in the decompressed chunk
  uint32_t size = 0;        // data bytes
};

struct RecoveredBag {
  std::string path;
  std::vector<RecoveredConnection> connections;
  std::vector<RecoveredChunk> chunks;
  std::vector<RecoveredMessage> messages;  // in file order
  BagRecoveryStats stats;                  // recovered = true, reason = the `reason` given
};

/// Scans the records of the bag at `path` (see the file comment). Needs the
/// magic line and the file header record to be intact (else DataLoss); the
/// data section ends at the file header's index_pos when that lies inside
/// the file, else at the end of the file. `reason` is kept in stats.reason.
Status ScanBagRecords(const std::string& path, const std::string& reason, RecoveredBag* bag);

/// Reads the bytes of recovered messages, keeping the last decompressed
/// chunk (messages of one topic are read in nearly file order).
class RecoveredMessageReader {
 public:
  /// `bag` must outlive the reader.
  explicit RecoveredMessageReader(const RecoveredBag* bag);

  Status Read(const RecoveredMessage& message, std::vector<uint8_t>* bytes);

 private:
  const RecoveredBag* bag_;
  std::unique_ptr<BagFile> file_;
  int64_t cached_chunk_ = -1;
  std::vector<uint8_t> stored_;
  std::vector<uint8_t> chunk_;
};

}  // namespace swarmlio::io::internal
