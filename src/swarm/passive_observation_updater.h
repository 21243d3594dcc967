// Passive observations (docs/swarm.md sections 4 and 8): teammates'
// observations of this drone from their messages, each used in one scan, at
// the time the teammate saw this drone (the own IMU motion since then
// retrodicts the position). Internal to src/swarm.
#pragma once

#include <deque>

#include "dead_reckoning.h"
#include "measurement_updater.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/swarm/swarm_options.h"
#include "teammate_registry.h"
#include "teammate_state.h"

namespace swarmlio::swarm::internal {

class PassiveObservationUpdater final : public MeasurementUpdater {
 public:
  PassiveObservationUpdater(const SwarmOptions& options, TeammateRegistry* registry,
                            DroneEstimatorCounters* counters)
      : options_(options), registry_(registry), counters_(counters) {}
  const char* name() const override { return "passive_observation"; }

  /// An observation of this drone from a teammate's message (the inbox).
  void Queue(PendingPassive observation) { pending_.push_back(std::move(observation)); }
  /// Teammate `sender` restarted: its observations are of its old session.
  void ForgetSender(int sender);

  /// Appends the scan's motion to the history, then the terms; the pending
  /// observations are used (or dropped) in this scan whatever the options.
  void AddTerms(const UpdaterScan& scan, ObservationGate* gate, ScanReport* report) override;

 private:
  SwarmOptions options_;
  TeammateRegistry* registry_;
  DroneEstimatorCounters* counters_;
  std::deque<PendingPassive> pending_;
  // Own propagated accelerations of the last seconds: their double integral
  // moves a passive observation's ego position from t_k back to t_j together
  // with the state's velocity (dead_reckoning.h, docs/swarm.md section 8).
  DeadReckoningTrack dead_reckoning_;
};

}  // namespace swarmlio::swarm::internal
