// SimulatedNetwork: N drone endpoints (Transport) on one simulated medium,
// for replaying several drones in one process on recorded time.
//
//   std::unique_ptr<net::SimulatedNetwork> network;
//   SWARMLIO_RETURN_IF_ERROR(net::SimulatedNetwork::Create(options, {0, 1, 2}, &network));
//   net::Transport* drone1 = network->Endpoint(1);
//   drone1->Send(t_ns, net::kBroadcastId, packet.data(), packet.size());
//   network->Endpoint(2)->Poll(t_ns, &datagrams);   // what reached drone 2 by t_ns
//
// Determinism: every directed link has its own random stream, seeded from
// (options.seed, from, to) with SplitMix64 and drawn from std::mt19937_64
// (fully specified by the standard) through hand-written distributions that
// use only IEEE arithmetic (no <random> distributions, no libm), so the same
// seed and the same sequence of Send calls per link give the same deliveries
// on every platform; nothing depends on hash-map order or addresses. Links
// do not share streams, so adding a drone or traffic on another link does not
// change a link's outcomes.
//
// Causality: a replay calls Send and Poll in non-decreasing time and, at one
// instant, makes every Send before any Poll (see docs/network.md, "Driving
// the network from a replay"); a packet whose delivery time is before the
// first Poll after it was sent is returned by that Poll with its true
// arrival_ns.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/network_options.h"
#include "swarmlio/net/transport.h"

namespace swarmlio::net {

/// Counters of one directed link (from -> to).
struct LinkStats {
  uint64_t sent = 0;           // packets handed to the link
  uint64_t delivered = 0;      // copies returned by Poll (duplicates included)
  uint64_t dropped_loss = 0;   // lost (loss_probability)
  uint64_t dropped_queue = 0;  // dropped by the bandwidth queue
  uint64_t duplicated = 0;     // extra copies created
  uint64_t reordered = 0;      // delivered after a packet sent later on this link
  uint64_t bytes_sent = 0;
  uint64_t bytes_delivered = 0;
  double latency_sum_s = 0.0;  // over delivered copies (arrival - send)
  double latency_max_s = 0.0;

  /// Copies still in flight.
  uint64_t InFlight() const { return sent + duplicated - delivered - dropped_loss - dropped_queue; }
  LinkStats& operator+=(const LinkStats& other);
};

class SimulatedNetwork {
 public:
  /// InvalidArgument for invalid options, an invalid or repeated drone id, or
  /// an override naming a drone that is not in `drone_ids`.
  static Status Create(const NetworkOptions& options,
                       const std::vector<int>& drone_ids,
                       std::unique_ptr<SimulatedNetwork>* network);

  ~SimulatedNetwork();
  SimulatedNetwork(const SimulatedNetwork&) = delete;
  SimulatedNetwork& operator=(const SimulatedNetwork&) = delete;

  /// The endpoint of drone `drone_id` (owned by the network), nullptr if absent.
  Transport* Endpoint(int drone_id);
  /// Drone ids, ascending.
  const std::vector<int>& drone_ids() const;

  /// Counters of link from -> to (zeros for an unknown pair).
  LinkStats Stats(int from_id, int to_id) const;
  /// Sum over all links.
  LinkStats TotalStats() const;
  /// Earliest arrival time still pending at any endpoint, or INT64_MAX (lets
  /// an event-driven replay wake receivers exactly at arrivals).
  int64_t NextArrivalNs() const;

 private:
  class Impl;
  class EndpointImpl;
  explicit SimulatedNetwork(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::net
