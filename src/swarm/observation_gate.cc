#include "observation_gate.h"

#include <string>
#include <utility>
#include <vector>

#include "factors/constant_block_cost.h"

namespace swarmlio::swarm::internal {

void ObservationGate::Begin(const SwarmState* x, double gate_sigma, bool frozen, bool exact) {
  x_ = x;
  gate_sigma_ = gate_sigma;
  frozen_ = frozen;
  exact_ = exact;
  rejected_ = 0;
  model_.Clear();
  estimated_.clear();
  considered_.clear();
}

bool ObservationGate::Add(std::unique_ptr<ceres::CostFunction> cost, int teammate_id,
                          const Eigen::Vector3d& innovation, const Eigen::Matrix3d& S) {
  if (gate_sigma_ > 0.0 && Mahalanobis2(innovation, S) > gate_sigma_ * gate_sigma_) {
    ++rejected_;
    return false;
  }
  if (frozen_ && exact_) {
    std::vector<double> T(GlobalExtrinsic::kAmbientSize);
    x_->teammate(teammate_id).ToParameters(T.data());
    model_.Add(std::make_unique<ConstantBlockCost>(std::move(cost), 1, std::move(T)),
               {lio::StateKey::Ego()});
    return true;
  }
  model_.Add(std::move(cost), {lio::StateKey::Ego(), lio::StateKey::Extrinsic(teammate_id)});
  (frozen_ ? considered_ : estimated_).insert(teammate_id);
  return true;
}

void ObservationGate::FillRequest(lio::UpdateRequest* request) {
  if (!model_.empty()) request->models.push_back(&model_);
  request->select_teammates = true;
  request->estimated_teammates.assign(estimated_.begin(), estimated_.end());
  request->considered_teammates.assign(considered_.begin(), considered_.end());
}

}  // namespace swarmlio::swarm::internal
