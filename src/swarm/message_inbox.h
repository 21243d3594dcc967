// The per-drone component's inbox (docs/swarm.md section 5): each received
// message goes at once to the one owner of what it carries. Clock-sync
// requests to the broadcaster, responses and teammates' states to the clock
// synchronisation; T_Gj_Gi (a teammate identified this drone) and T_Gj_Gk
// (its matches) to the teammate registry, its gravity to the gravity
// updater; a state to the registry (the newest state, sessions and
// restarts), the detector (the broadcast trajectory) and, for each
// observation of this drone it carries, the passive updater; a teammate's
// airframe to the detector. Bad or own messages are counted and ignored. An extrinsic entry's
// frames (the wire's neutral T_Ga_Gb, a = sender) are named here, once: T_Gj_Gi or T_Gj_Gk.
// Internal to src/swarm.
#pragma once

#include <cstdint>
#include <map>

#include "broadcaster.h"
#include "gravity_updater.h"
#include "passive_observation_updater.h"
#include "swarmlio/net/clock_sync.h"
#include "swarmlio/net/message_channel.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/teammate/teammate_detector.h"
#include "teammate_registry.h"

namespace swarmlio::swarm::internal {

/// The owners the inbox hands messages to (not owned; clock_sync may be null).
struct InboxOwners {
  TeammateRegistry* registry = nullptr;
  PassiveObservationUpdater* passive = nullptr;
  GravityUpdater* gravity = nullptr;
  Broadcaster* broadcaster = nullptr;
  teammate::TeammateDetector* detector = nullptr;
  net::ClockSync* clock_sync = nullptr;
  DroneEstimatorCounters* counters = nullptr;
};

/// This drone's own session: teammates hear it with its first state,
/// sent once the odometry started (after an in-flight initialization).
struct OwnSession {
  bool started = false;
  int64_t started_ns = 0;
};

class MessageInbox {
 public:
  MessageInbox(int self_id, const SwarmOptions& options, const InboxOwners& owners)
      : self_id_(self_id), options_(options), to_(owners) {}

  void Route(const net::ReceivedMessage& message, const OwnSession& own);

 private:
  void OnTimeSync(const net::TimeSyncMessage& t, int64_t arrival_ns);
  void OnExtrinsics(const net::GlobalExtrinsicMessage& g, const OwnSession& own);
  void OnState(const net::EgoStateMessage& received, int64_t arrival_ns);
  void OnAirframe(const net::AirframeMessage& a);
  // j rebooted (its session changed): what this drone had of it goes.
  void OnRestart(int j, int64_t arrival_ns);
  // j's observations of this drone in message `m` (stamps in the own clock)
  // to the passive updater, each once.
  void QueueObservations(const net::EgoStateMessage& received, const net::EgoStateMessage& m);
  // A sender's stamp on the own clock; false while its offset is unknown.
  bool ToLocal(int sender_id, int64_t sender_stamp_ns, int64_t* local_ns) const;
  // Whether a teammate's message was made after this drone's session began
  // (by max_message_age_s): false before the odometry started or while the
  // sender's clock offset is unknown.
  bool MadeInThisSession(int sender_id, int64_t sender_stamp_ns, const OwnSession& own) const;
  // Whether a sender's message about teammate k is from k's current session
  // (k restarted: not before this drone heard the new session +
  // max_message_age_s); true when k never restarted.
  bool MadeInSessionOf(int teammate_id, int sender_id, int64_t sender_stamp_ns) const;

  int self_id_;
  SwarmOptions options_;
  InboxOwners to_;
  std::map<int, int64_t> clock_sessions_;  // session_start_ns each teammate's clock belongs to
};

}  // namespace swarmlio::swarm::internal
