// BagSource over a rosbag2 SQLite3 file (.db3): table topics(id, name, type,
// serialization_format, offered_qos_profiles) gives the connections (type as
// datatype, serialization_format as encoding), table messages(id, topic_id,
// timestamp, data) the messages, per topic in timestamp order (ties: id),
// timestamp as bag time. Opened read-only through libsqlite3; a file SQLite
// cannot read (corrupt, truncated, not rosbag2) is a DataLoss naming it.
#pragma once

#include <memory>
#include <string>

#include "src/io/bag_source.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

Status OpenDb3Source(const std::string& path, std::unique_ptr<BagSource>* source);

/// True when the file at `path` starts with the SQLite 3 magic.
bool HasSqliteMagic(const std::string& path);

}  // namespace swarmlio::io::internal
