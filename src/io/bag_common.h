// Helpers shared by the bag reader, writer and info: opening a bag for
// reading and turning rosbag exceptions into Status values.
#pragma once

#include <rosbag/bag.h>
#include <rosbag/structures.h>

#include <exception>
#include <string>
#include <vector>

#include "src/io/bag_precheck.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// Opens `path` read-only after PrecheckBagFile (bag_precheck.h; chunk
/// contents are verified when `verify_chunks`): NotFound if there is no such
/// file, DataLoss or IoError with the path and the reason if it cannot be read.
/// `precheck` (may be null) tells whether a DataLoss came from a damaged index.
Status OpenBagForReading(const std::string& path,
                         bool verify_chunks,
                         rosbag::Bag* bag,
                         BagPrecheckResult* precheck = nullptr);

/// Routes rosbag's console_bridge messages (e.g. about corrupt index
/// entries) to glog VLOG(1) instead of stdout/stderr, unless the process
/// installed its own console_bridge handler. Idempotent.
void RouteRosbagLogsToGlog();

/// Status for an exception thrown by rosbag while doing `action` on `path`.
Status StatusFromException(const std::string& path,
                           const std::string& action,
                           const std::exception& e);

/// Status for a non-std exception thrown while doing `action` on `path`.
Status UnknownExceptionStatus(const std::string& path, const std::string& action);

}  // namespace swarmlio::io::internal
