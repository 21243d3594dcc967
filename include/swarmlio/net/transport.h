// Transport: moves opaque packets between drones. The codec sits above it;
// the simulated network (simulated_network.h) and the UDP transport
// (docs/network.md, "Real UDP transport") implement it, so the layers above
// cannot tell them apart.
//
// Time is passed in, never read from a clock: the replay runs on recorded
// time, and a real transport is driven with the drone's own clock
// (`now_ns` = the stamp of the sensor data being processed). Times are int64
// nanoseconds (docs/conventions.md, "Time"), so delivery order is exact.
//
// Packets are best effort: a packet may be lost, duplicated, delayed or
// reordered. A Transport is used from one thread (its drone's).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {

/// One received packet.
struct Datagram {
  /// The sender as the transport sees it (simulation: the true sender; UDP:
  /// looked up from the source address, -1 when unknown). Unauthenticated:
  /// trust only the sender id inside the authenticated packet.
  int source_id = -1;
  int64_t arrival_ns = 0;  // when it arrived, on the receiver's time line [ns]
  std::vector<uint8_t> bytes;
};

class Transport {
 public:
  virtual ~Transport() = default;

  /// This endpoint's drone id.
  virtual int self_id() const = 0;

  /// Sends `size` bytes at time `now_ns` to drone `destination_id`, or to
  /// every other drone when it is kBroadcastId. InvalidArgument for an empty
  /// or oversized (> kMaxPacketBytes) packet or for sending to oneself,
  /// NotFound for an unknown destination, IoError when the medium fails.
  /// Ok does not mean delivered.
  virtual Status Send(int64_t now_ns, int destination_id, const uint8_t* data, size_t size) = 0;

  /// Appends to `*received` every packet that arrived at or before `now_ns`
  /// and was not returned yet, in arrival order (ties: send order).
  virtual Status Poll(int64_t now_ns, std::vector<Datagram>* received) = 0;
};

}  // namespace swarmlio::net
