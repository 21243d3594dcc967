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

/// Ok if `path` looks like a complete, consistent ROS1 2.0 bag; DataLoss (or
/// IoError if it cannot be read) with the path and the problem otherwise.
/// Files that start with another "#ROSBAG V" version are passed through
/// unchecked (rosbag handles them).
Status PrecheckBagFile(const std::string& path, const BagPrecheckOptions& options);

}  // namespace swarmlio::io::internal
