// The per-drone component's broadcaster (docs/swarm.md "Broadcast budget",
// docs/network.md section 2.2): after each scan, the own state with what
// fits the byte budget of clock-sync echoes, observations of teammates and
// repeats, the own airframe when due, and the own T_Gi_Gj estimates with
// gravity when new or due; the
// answers to the teammates' clock-sync requests and the own requests when
// the driver takes the messages. Internal to src/swarm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "swarmlio/net/clock_sync.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/broadcast_budget.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/airframe.h"
#include "swarmlio/teammate/observation.h"
#include "teammate_registry.h"

namespace swarmlio::swarm::internal {

/// What the broadcast of one scan is made of.
struct BroadcastScan {
  int64_t t_k = 0;                // the scan end (own clock)
  const SwarmState* x = nullptr;  // the posterior
  const Eigen::MatrixXd* P = nullptr;
  bool degenerate = false;                              // the scan's degeneracy flag
  int64_t session_start_ns = 0;                         // the odometry's initialization stamp
  Eigen::Vector3d last_gyro = Eigen::Vector3d::Zero();  // the newest gyro sample [rad/s]
  const std::vector<teammate::TeammateObservation>* observations = nullptr;  // this scan's
};

class Broadcaster {
 public:
  /// `airframe`: this drone's own, announced every options.airframe_period_s.
  /// `clock_sync` may be null (no clock synchronisation); the pointers outlive the broadcaster.
  Broadcaster(int self_id,
              const SwarmOptions& options,
              const teammate::AirframeDescription& airframe,
              net::ClockSync* clock_sync,
              TeammateRegistry* registry,
              DroneEstimatorCounters* counters)
      : self_id_(self_id),
        options_(options),
        airframe_(airframe),
        clock_sync_(clock_sync),
        registry_(registry),
        counters_(counters),
        budget_(options.broadcast_budget) {}

  /// The scan's messages (queued until TakeMessages).
  void Broadcast(const BroadcastScan& scan);
  /// Teammates whose blocks left the state: new again when identified again
  /// (their T_Gi_Gj entry goes out at once).
  void ForgetTeammates(const std::vector<int>& ids);
  /// A teammate's clock-sync request, answered in TakeMessages.
  void QueueSyncRequest(const net::TimeSyncMessage& request, int64_t arrival_ns);
  /// The queued messages, then the clock-sync answers and the own due
  /// requests stamped `now_ns` (the newest sensor stamp; none before one).
  void TakeMessages(int64_t now_ns, std::vector<net::SwarmMessage>* messages);

 private:
  struct Pass;
  // The steps of Broadcast, in priority order (broadcaster.cc's header).
  void MakeState(Pass* pass);
  void AnnounceAirframe(Pass* pass);
  void AddEchoes(net::ClockSync::EchoSelection selection, int most, Pass* pass);
  void ChooseNewExtrinsics(Pass* pass);
  void SortObservations(Pass* pass);
  void AddObservations(const std::vector<int>& ids, Pass* pass);
  void AddRepeats(Pass* pass);
  void AddClockItems(Pass* pass);
  void QueueState(const Pass& pass);
  void SendExtrinsics(Pass* pass);
  // Keeps the observations of the state message `m` that the next message
  // repeats (SwarmOptions::repeat_observations), moved into G_i.
  void RememberForRepeat(const net::EgoStateMessage& m,
                         const SwarmState& x,
                         const Eigen::MatrixXd& P);

  int self_id_;
  SwarmOptions options_;
  teammate::AirframeDescription airframe_;
  net::ClockSync* clock_sync_;
  TeammateRegistry* registry_;
  DroneEstimatorCounters* counters_;
  // What leaves: a byte budget, and the order in which teammates' items
  // share it (broadcast_budget.h).
  BroadcastBudget budget_;
  SendRotation observation_rotation_;
  SendRotation extrinsic_rotation_;
  int64_t last_extrinsic_broadcast_ns_ = 0;
  bool broadcast_extrinsics_once_ = false;
  int64_t last_airframe_ns_ = 0;
  bool airframe_announced_ = false;
  // This scan's observations to send again with the next state message
  // (SwarmOptions::repeat_observations), in G_i; age_ns unset.
  std::vector<net::PastObservation> repeat_;
  int64_t repeat_stamp_ns_ = 0;
  std::vector<net::SwarmMessage> messages_;
  // Requests to answer when the messages are taken (t3 = send time).
  std::vector<std::pair<net::TimeSyncMessage, int64_t>> sync_requests_;  // with arrival
};

}  // namespace swarmlio::swarm::internal
