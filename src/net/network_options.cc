#include "swarmlio/net/network_options.h"

namespace swarmlio::net {

std::string LinkOverride::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (error.empty() && from_id >= 0 && from_id == to_id) {
    error = "to_id: equals from_id (" + std::to_string(from_id) + "); a link joins two drones";
  }
  return error;
}

const LinkOptions& NetworkOptions::ForLink(int from_id, int to_id) const {
  const LinkOptions* chosen = &default_link;
  for (const LinkOverride& o : links) {
    if ((o.from_id < 0 || o.from_id == from_id) && (o.to_id < 0 || o.to_id == to_id)) {
      chosen = &o.link;
    }
  }
  return *chosen;
}

}  // namespace swarmlio::net
