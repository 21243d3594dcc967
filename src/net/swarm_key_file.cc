#include "swarmlio/net/swarm_key_file.h"

#include <algorithm>
#include <fstream>
#include <iterator>

namespace swarmlio::net {

Status LoadSwarmKeyFile(const std::string& path, SwarmKey* key) {
  std::ifstream in(path);
  if (!in) return Status::IoError(path + ": cannot open the key file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const Status status = SwarmKey::FromHex(text, key);
  std::fill(text.begin(), text.end(), '\0');  // do not leave the key in freed memory
  return status.WithContext(path);
}

}  // namespace swarmlio::net
