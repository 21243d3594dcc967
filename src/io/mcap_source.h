// BagSource over an MCAP file (mcap_scan.h): its channels as connections
// (topic, schema name as datatype, message encoding; a "ros1" channel's
// "md5sum" metadata as MD5), per topic the messages in log-time order
// (ties: file order), log time as bag time.
#pragma once

#include <memory>
#include <string>

#include "src/io/bag_source.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// Opens the MCAP file at `path`; `options.recover` as for ROS1 bags.
Status OpenMcapSource(const std::string& path,
                      const BagSourceOptions& options,
                      std::unique_ptr<BagSource>* source);

/// True when the file at `path` starts with the MCAP magic (false when it
/// cannot be read).
bool HasMcapMagic(const std::string& path);

}  // namespace swarmlio::io::internal
