// Clock synchronisation in simulation: N drones with offset and drifting
// clocks run ClockSync over MessageChannels on a seeded SimulatedNetwork,
// event by event (requests, arrivals, replies after a turnaround; with
// exchange = state_echo, a state broadcast every 100 ms of each drone's
// clock). Used by the clock-sync tests and the figures tool
// (tools/sim/swarmlio_clock_sync_figures.cc, docs/network.md).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/clock_sync.h"
#include "swarmlio/net/message_channel.h"
#include "swarmlio/net/simulated_network.h"

namespace swarmlio::net {

/// A drone's clock: local = epoch + t + drift * t, t = true time since the
/// simulation start [ns].
struct SimulatedClock {
  int64_t epoch_ns = 0;
  double drift = 0.0;  // rate error, 20e-6 = 20 ppm

  int64_t Local(int64_t true_ns) const;
  /// The first true time at which the local clock reads >= local_ns.
  int64_t TrueAt(int64_t local_ns) const;
};

/// Offsets of +-0.5 s and drifts of +-20 ppm (relative drift up to 40 ppm),
/// three drones.
std::vector<SimulatedClock> SwarmClocks();

class ClockSyncSimulation {
 public:
  static constexpr int64_t kStatePeriodNs = 100'000'000;

  /// InvalidArgument for invalid network or sync options.
  static Status Create(const NetworkOptions& network_options,
                       std::vector<SimulatedClock> clocks,
                       const ClockSyncOptions& sync_options,
                       int64_t turnaround_ns,
                       std::unique_ptr<ClockSyncSimulation>* out);
  ~ClockSyncSimulation();

  /// Runs every event up to true time `end_ns`. An error of a channel or
  /// of a received message ends the run with that error.
  Status RunUntil(int64_t end_ns);

  /// True offset of j's clock relative to i's at the current time [ns].
  int64_t TrueOffset(int i, int j) const;
  ClockOffsetEstimate Estimate(int i, int j) const;
  /// Estimate minus truth [ns].
  double Error(int i, int j) const;
  const ClockSync& sync(int i) const { return *syncs_[i]; }
  ClockSync& mutable_sync(int i) { return *syncs_[i]; }
  const SimulatedClock& clock(int i) const { return clocks_[i]; }
  int64_t now_ns() const { return now_ns_; }
  int size() const { return static_cast<int>(clocks_.size()); }

 private:
  struct PendingReply {
    int64_t send_ns;  // true time
    int from;
    TimeSyncMessage reply;
  };
  struct PendingState {
    int64_t send_ns;        // true time
    int64_t local_send_ns;  // the sender's clock
    int from;
    EgoStateMessage state;
  };

  ClockSyncSimulation(std::vector<SimulatedClock> clocks, int64_t turnaround_ns, bool states);
  int64_t NextEventNs() const;
  Status SendDue(int64_t t);
  Status Receive(int64_t t);
  void MakeState(int i);

  std::vector<SimulatedClock> clocks_;
  int64_t turnaround_ns_;
  PacketCodec codec_;
  std::unique_ptr<SimulatedNetwork> network_;
  std::vector<MessageChannel> channels_;
  std::vector<std::unique_ptr<ClockSync>> syncs_;
  std::vector<PendingReply> replies_;
  bool states_;                         // exchange = state_echo
  std::vector<int64_t> next_state_ns_;  // per drone, its clock
  std::vector<PendingState> states_out_;
  int64_t now_ns_ = 0;
};

/// Error figures of every pair, checked once per second of true time.
struct ClockSyncFigures {
  double max_abs_ms = 0;         // after settle_s
  double rms_ms = 0;             // after settle_s
  double max_normalised = 0;     // max |error| / std after settle_s
  double within_3_sigma = 0;     // fraction of checks with |error| <= 3 std
  double within_2ms_from_s = 0;  // every check from this time on is within 2 ms
  int checks = 0;
};

/// One link for every pair, seeds 1..`seeds`, `end_s` seconds each.
Status RunClockSyncCase(const LinkOptions& link,
                        const ClockSyncOptions& options,
                        int seeds,
                        int end_s,
                        int settle_s,
                        const std::vector<SimulatedClock>& clocks,
                        ClockSyncFigures* figures);

}  // namespace swarmlio::net
