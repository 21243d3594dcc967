// SwarmReplay: runs the estimators of N drones in one process on recorded
// time. Records of all bags are consumed in stamp order (ties: lower drone
// index first), so a run is a deterministic function of the logs and options.
// Inter-drone messages go through a seeded simulated network (net::
// SimulatedNetwork behind the net::Transport interface a UDP transport will
// implement): after every scan a drone broadcasts its EgoStateMessage, and
// before each of its records it polls what has arrived by that record's stamp.
// The network runs on true time: each drone's stamps are mapped through its
// manifest TrueClock (offset, drift; identity when absent), packets arrive on
// the receiver's clock, and the drones synchronise their clocks themselves
// (swarm.synchronize_clocks). Every drone is a swarm::DroneEstimator: what arrives
// is delivered to it, what it produces is broadcast. single_agent (the
// ablation, the paper's FAST-LIO2 column) fuses no mutual observation;
// messages still flow, so teammates are identified and reported through
// the matched extrinsic (a loosely coupled baseline).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/message_channel.h"
#include "swarmlio/net/network_options.h"
#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/simulated_network.h"
#include "swarmlio/replay/drone_runner.h"
#include "swarmlio/driver/manifest.h"

namespace swarmlio::replay {

struct ReplayProgress {
  int64_t stamp_ns = 0;        // the record just consumed
  int64_t start_stamp_ns = 0;  // earliest bag time over all drones
  int64_t end_stamp_ns = 0;    // latest bag time over all drones
  int64_t records = 0;         // consumed so far
  double Fraction() const;
};

struct ReplayOptions {
  /// Stop after this much log time from the start [s]; 0 = the whole logs.
  double max_duration_s = 0.0;
  /// Called every `progress_every_records` records (tool-side progress bar).
  std::function<void(const ReplayProgress&)> on_progress;
  int64_t progress_every_records = 2000;
  /// Ablation: no mutual observation is fused (messages still flow).
  bool single_agent = false;
  /// The simulated network (latency, jitter, loss, reordering, duplication).
  net::NetworkOptions network;
  /// Offline re-run of live drones (docs/online.md): drone name -> packet log
  /// (`<name>_received.bin` of swarmlio_live). Such a drone receives exactly
  /// the logged datagrams at their logged arrival times instead of the
  /// simulated network; what it sends is discarded. A truncated or corrupt
  /// log is re-run up to the damage and Run() returns its DataLoss.
  std::map<std::string, std::string> received_packets;
  /// Drone name -> record stamps of scans to leave out: for a re-run, the
  /// scans the live run dropped (`<name>_dropped_scans.txt` of swarmlio_live,
  /// ReadDroppedScans), so that it processes exactly the scans the live run
  /// processed and reproduces its trajectory. Stamps without a scan are ignored.
  std::map<std::string, std::vector<int64_t>> dropped_scans;
  /// Key of the packet codec (the live swarm's key for received_packets);
  /// default: SwarmKey::ForSimulation(network.seed).
  std::optional<net::SwarmKey> key;
};

/// What one drone's channel received.
struct DroneTraffic {
  int64_t received = 0;         // messages delivered by Poll
  int64_t ego_states = 0;       // of which EgoStateMessage
  int64_t sent = 0;             // messages broadcast
  net::ChannelStats channel;    // rejected, duplicates, ...
};

class SwarmReplay {
 public:
  /// Opens every drone's bag (all of them: every error is reported, joined).
  static Status Create(const driver::SwarmManifest& manifest, std::unique_ptr<SwarmReplay>* replay);

  /// Runs to the end of all logs (or max_duration_s). On a read error the
  /// other drones still run to the end; the first error is returned and the
  /// results so far are kept. InvalidArgument for invalid network options.
  Status Run(const ReplayOptions& options);

  /// Per-drone message counts and the network's link statistics (after Run).
  const DroneTraffic& traffic(int i) const { return traffic_[i]; }
  net::LinkStats LinkStats(int from, int to) const;

  int num_drones() const { return static_cast<int>(runners_.size()); }
  const DroneRunner& drone(int i) const { return *runners_[i]; }
  const driver::SwarmManifest& manifest() const { return manifest_; }

 private:
  SwarmReplay() = default;

  driver::SwarmManifest manifest_;
  std::vector<std::unique_ptr<DroneRunner>> runners_;
  Status SetUpNetwork(const ReplayOptions& options);
  Status OpenRecordedPackets(const ReplayOptions& options);
  Status SkipDroppedScans(const ReplayOptions& options);
  int FindDrone(const std::string& name) const;  // -1: none of that name
  Status Broadcast(int drone, int64_t now_ns);
  std::vector<net::SwarmMessage> outbox_;

  std::unique_ptr<net::SimulatedNetwork> network_;
  net::PacketCodec codec_;
  std::vector<std::unique_ptr<net::MessageChannel>> channels_;
  std::vector<std::unique_ptr<net::Transport>> recorded_;  // received_packets transports
  Status recording_damage_;  // the first damaged received_packets log (re-run up to the damage)
  std::vector<DroneTraffic> traffic_;
  int64_t start_stamp_ns_ = 0;
  int64_t end_stamp_ns_ = 0;
};

}  // namespace swarmlio::replay
