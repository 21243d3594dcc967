// Structural check of a ROS1 bag (format 2.0) before rosbag opens it.
//
// rosbag trusts the lengths and offsets stored in the file: a truncated or
// corrupt file makes it allocate buffers of up to 4 GiB, or read outside its
// chunk buffer (a crash), before any exception. This check walks what
// rosbag will rely on, every length checked against the file size:
//   - always: the magic line, the file header record, the index section
//     (connection and chunk-info records), each chunk's record header and
//     its index-data records (message offsets inside the chunk);
//   - with verify_chunk_records: also every chunk's content (decompressed
//     with roslz4 / bzip2 when compressed), checking each indexed message
//     record's header and data length. This is one extra pass over the file.
#pragma once

#include <string>

#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

struct BagPrecheckOptions {
  bool verify_chunk_records = false;
};

struct BagPrecheckResult {
  /// Set with a DataLoss error when the file header is intact but the index
  /// is not usable: not indexed (index_pos = 0, the recorder died), index
  /// beyond the end of the file (truncated), or an index section that is
  /// cut off or corrupt. The records can then be scanned (bag_recovery.h).
  bool index_damaged = false;
};

/// Ok if `path` looks like a complete, consistent ROS1 2.0 bag; DataLoss (or
/// IoError if it cannot be read) with the path and the problem otherwise.
/// Files that start with another "#ROSBAG V" version are passed through
/// unchecked (rosbag handles them). `result` may be null.
Status PrecheckBagFile(const std::string& path,
                       const BagPrecheckOptions& options,
                       BagPrecheckResult* result = nullptr);

}  // namespace swarmlio::io::internal
