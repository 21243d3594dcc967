// The gate every mutual-observation term of a scan passes (docs/swarm.md
// section 4): the chi-square test of its innovation, and how the extrinsic
// block it names enters the update after a degenerate own scan
// (SwarmOptions::degeneracy_policy): estimated, considered (its covariance in
// the gain, not corrected), or held exact. It collects the scan's terms as
// one measurement model and the teammate blocks the update estimates.
// Internal to src/swarm.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <memory>
#include <set>

#include "observation_terms.h"
#include "swarmlio/lio/scan_stages.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/swarm_options.h"

namespace swarmlio::swarm::internal {

class ObservationGate {
 public:
  /// A new scan: no terms; `frozen`: the extrinsics are not corrected in
  /// this scan (`exact`: held at their values, else considered).
  void Begin(const SwarmState* x, double gate_sigma, bool frozen, bool exact);

  /// Adds the term on the ego block and teammate `teammate_id`'s extrinsic
  /// unless its innovation (prediction minus measurement, covariance S) fails
  /// the gate. Returns whether it was added.
  bool Add(std::unique_ptr<ceres::CostFunction> cost, int teammate_id,
           const Eigen::Vector3d& innovation, const Eigen::Matrix3d& S);

  bool frozen() const { return frozen_; }
  int rejected() const { return rejected_; }
  /// The scan's terms, the blocks estimated and considered, into the request.
  void FillRequest(lio::UpdateRequest* request);

 private:
  const SwarmState* x_ = nullptr;
  double gate_sigma_ = 0.0;
  bool frozen_ = false;
  bool exact_ = false;
  int rejected_ = 0;
  MutualObservationModel model_;
  std::set<int> estimated_;
  std::set<int> considered_;
};

}  // namespace swarmlio::swarm::internal
