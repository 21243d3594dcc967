// The one conversion between a drone's airframe (teammate::AirframeDescription,
// YAML `airframe:`) and its wire form (net::AirframeMessage), each way: the
// broadcaster announces the own airframe with ToAirframeMessage, the inbox
// hands a teammate's to the detector through FromAirframeMessage. Internal
// to src/swarm.
#pragma once

#include <cstdint>

#include "swarmlio/net/messages.h"
#include "swarmlio/teammate/airframe.h"

namespace swarmlio::swarm::internal {

/// Drone `sender_id`'s announcement of `airframe` at `stamp_ns` (its clock).
net::AirframeMessage ToAirframeMessage(int sender_id,
                                       int64_t stamp_ns,
                                       const teammate::AirframeDescription& airframe);

/// The description a teammate announced; false (and `airframe` untouched)
/// when the shape is unknown or the description is invalid
/// (AirframeDescription::Validate).
bool FromAirframeMessage(const net::AirframeMessage& message,
                         teammate::AirframeDescription* airframe);

}  // namespace swarmlio::swarm::internal
