// Reads the swarm's pre-shared key from a file (docs/network.md, "Security";
// docs/online.md): 64 hex digits, as written by
//   head -c 32 /dev/urandom | xxd -p -c 64 > swarm.key && chmod 600 swarm.key
#pragma once

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/net/swarm_key.h"

namespace swarmlio::net {

/// IoError when `path` cannot be read, InvalidArgument (naming the file)
/// when it does not hold exactly 64 hex digits (surrounding whitespace ignored).
Status LoadSwarmKeyFile(const std::string& path, SwarmKey* key);

}  // namespace swarmlio::net
