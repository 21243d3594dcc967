// The scans a live run dropped (docs/online.md, "Offline re-run"): the live
// process writes one line per dropped scan to `<name>_dropped_scans.txt`,
//   # record_stamp_ns reason
//   1700000000123456789 queue
//   1700000000223456789 backlog
// and the offline re-run (ReplayOptions::dropped_scans) leaves those scans out.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::replay {

/// The file's first line.
inline constexpr const char* kDroppedScansHeader = "# record_stamp_ns reason\n";

/// Reads such a file into the stamps, in file order. Lines starting with '#'
/// and empty lines are skipped. IoError when the file cannot be read;
/// DataLoss naming the line for a line that is not `<int64> queue|backlog`
/// (nothing is returned then: a damaged file would re-run the wrong scans).
Status ReadDroppedScans(const std::string& path, std::vector<int64_t>* stamps_ns);

}  // namespace swarmlio::replay
