// The mutual-observation residual terms of one scan (swarm::DroneEstimator,
// docs/swarm.md section 4): the model the update re-evaluates at every
// iteration, the share of an observation's information, and the
// covariance hygiene every input from the network goes through. Internal to
// src/swarm.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <memory>
#include <utility>
#include <vector>

#include "swarmlio/lio/measurement_model.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/swarm_options.h"

namespace swarmlio::swarm::internal {

// The mutual observations of one scan: factors built at the front end; the
// update re-evaluates them at every iteration (their residuals are exact
// functions of the state; only the noise is fixed at the prediction).
class MutualObservationModel final : public lio::MeasurementModel {
 public:
  const char* name() const override { return "mutual_observation"; }
  Status Linearize(const SwarmState&, std::vector<lio::ResidualTerm>* terms) override {
    for (size_t k = 0; k < costs_.size(); ++k) terms->push_back({costs_[k].get(), blocks_[k]});
    return Status::Ok();
  }
  bool ReleaseTerms(std::vector<lio::OwnedResidualTerm>* terms) override {
    for (size_t k = 0; k < costs_.size(); ++k) {
      terms->push_back({std::move(costs_[k]), std::move(blocks_[k])});
    }
    Clear();
    return true;
  }
  void Clear() {
    costs_.clear();
    blocks_.clear();
  }
  void Add(std::unique_ptr<ceres::CostFunction> cost, std::vector<lio::StateKey> blocks) {
    costs_.push_back(std::move(cost));
    blocks_.push_back(std::move(blocks));
  }
  bool empty() const { return costs_.empty(); }

 private:
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  std::vector<std::vector<lio::StateKey>> blocks_;
};

// A covariance from the network or the detector, made symmetric positive
// definite: eigenvalues clamped to at least `floor` ((1 mm)^2 by default).
// The network checks only finiteness and non-negative variances, so an
// indefinite matrix from a broken teammate must not reach a factor.
template <int N>
Eigen::Matrix<double, N, N> Regularized(const Eigen::Matrix<double, N, N>& C, double floor = 1e-6) {
  using Matrix = Eigen::Matrix<double, N, N>;
  const Matrix S = 0.5 * (C + C.transpose());
  const Eigen::SelfAdjointEigenSolver<Matrix> eig(S);
  const Eigen::Matrix<double, N, 1> values = eig.eigenvalues().cwiseMax(floor);
  return eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
}

// Mahalanobis distance^2 of h - z under S.
inline double Mahalanobis2(const Eigen::Vector3d& e, const Eigen::Matrix3d& S) {
  return e.dot(S.ldlt().solve(e));
}

// The share of a mutual observation's information this drone takes
// (docs/swarm.md "Information sharing"): observation_information_share, or
// all of it while this drone's last scan was degenerate and the teammate's
// (its state with the observation) was not. Such a teammate skips the
// observation (skip_degenerate_teammates), so it is used here only. A
// teammate that reports degeneracy itself may fuse it too (it skips only
// while it is mostly well localized): the share stays, or both would take
// it at full weight and the swarm would count it twice.
inline double ObservationShare(const SwarmOptions& options, bool own_last_scan_degenerate,
                               bool teammate_degenerate) {
  return options.skip_degenerate_teammates && own_last_scan_degenerate && !teammate_degenerate
             ? 1.0
             : options.observation_information_share;
}

}  // namespace swarmlio::swarm::internal
