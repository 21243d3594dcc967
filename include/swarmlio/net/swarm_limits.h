// Limits shared by every module that handles drone ids or swarm packets.
//
// The original system disagreed with itself (MAX_DRONE_ID 40 in the estimator,
// 31 in udp_bridge; docs/network.md). Here there is one constant, and both the
// codec and the estimator's teammate bookkeeping must use it.
#pragma once

#include <cstddef>

namespace swarmlio::net {

/// Drone ids are 0 .. kMaxSwarmSize-1 (one byte on the wire).
inline constexpr int kMaxSwarmSize = 64;

/// Hard cap on one encoded packet (header + payload + tag). 1200 B stays below
/// the 1280 B IPv6 minimum MTU minus IP/UDP headers, so no packet is ever
/// fragmented on any link the swarm may use.
inline constexpr size_t kMaxPacketBytes = 1200;

/// Destination id meaning "every other drone".
inline constexpr int kBroadcastId = -1;

inline constexpr bool IsValidDroneId(int id) { return id >= 0 && id < kMaxSwarmSize; }

}  // namespace swarmlio::net
