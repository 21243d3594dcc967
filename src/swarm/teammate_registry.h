// The teammates one drone knows (docs/swarm.md sections 3 and 5): what their
// messages told (teammate_state.h) and which of them have an extrinsic block
// T_Gi_Gj in the state. Once per scan it adds the blocks of teammates newly
// identified (by trajectory match, by their own match of this drone, or
// through a teammate's match) and removes those lost or restarted; the
// detector tracks the teammates whose blocks exist. Internal to src/swarm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "scan_report.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/teammate_detector.h"
#include "teammate_state.h"

namespace swarmlio::swarm::internal {

class TeammateRegistry {
 public:
  /// `detector` (not owned) outlives the registry.
  TeammateRegistry(int self_id, const SwarmOptions& options, teammate::TeammateDetector* detector)
      : self_id_(self_id), options_(options), detector_(detector) {}

  /// What this drone knows of each teammate heard or seen so far.
  Teammates& teammates() { return teammates_; }
  const Teammates& teammates() const { return teammates_; }

  /// Teammate `sender` identified this drone: its T_Gj_Gi, used at the next scan.
  void SetMutual(int sender, const PendingMutual& mutual) { mutual_[sender] = mutual; }
  void ForgetMutual(int sender) { mutual_.erase(sender); }

  /// The scan at t_k: blocks of newly identified teammates in (their events
  /// in the report), of lost or restarted ones out; `detection` is this
  /// scan's (its observations mark their teammates seen).
  void UpdateBlocks(int64_t t_k, const teammate::ScanResult& detection, SwarmState* x,
                    Eigen::MatrixXd* P, ScanReport* report, DroneEstimatorCounters* counters);

  /// Every teammate in the posterior (x, P) at t_k, for the scan's output.
  std::vector<TeammateEstimate> Estimates(int64_t t_k, const SwarmState& x,
                                          const Eigen::MatrixXd& P, const ScanReport& report);

 private:
  // Teammates the detector identified by trajectory match in this scan.
  void AddMatched(int64_t t_k, const teammate::ScanResult& detection, SwarmState* x,
                  Eigen::MatrixXd* P, ScanReport* report);
  // Teammates that identified this drone (their T_Gj_Gi inverted).
  void AddMutual(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P, ScanReport* report);
  // Identification through teammates (docs/swarm.md): every k that a
  // first-hand teammate j identified and this drone has not.
  void AddThroughTeammates(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P, ScanReport* report);
  void RemoveLost(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P, ScanReport* report);
  // A second-hand block that has not fused enough own observations
  // (follow_source_until_observations) takes its source's newer estimate.
  bool FollowsSource(int id) const;
  // Replaces the block of `id` by T with covariance C and cross-covariances
  // `cross` (6 x n, the other rows of P; zero when independent).
  void ReplaceBlock(int id, const GlobalExtrinsic& T, const Eigen::Matrix<double, 6, 6>& C,
                    const Eigen::MatrixXd& cross, SwarmState* x, Eigen::MatrixXd* P);
  // The block of `id` enters the state at t_k with covariance C.
  void AddBlock(int id, int64_t t_k, const GlobalExtrinsic& T, const Eigen::Matrix<double, 6, 6>& C,
                SwarmState* x, Eigen::MatrixXd* P);

  int self_id_;
  SwarmOptions options_;
  teammate::TeammateDetector* detector_;
  Teammates teammates_;
  std::map<int, PendingMutual> mutual_;  // by sender
};

}  // namespace swarmlio::swarm::internal
