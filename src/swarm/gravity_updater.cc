#include "gravity_updater.h"

#include <memory>

#include "factors/gravity_alignment_factor.h"
#include "observation_terms.h"

namespace swarmlio::swarm::internal {

void GravityUpdater::Queue(int sender, const Eigen::Vector3d& g_in_Gj,
                           const Eigen::Matrix3d& covariance) {
  pending_[sender] = Pending{g_in_Gj, covariance};
}

void GravityUpdater::AddTerms(const UpdaterScan& scan, ObservationGate* gate,
                              ScanReport* report) {
  if (!options_.fuse_gravity || !scan.fusion_enabled || gate->frozen()) return;
  const SwarmState& x = *scan.x;
  for (int id : x.layout().teammate_ids()) {
    const auto it = pending_.find(id);
    if (it == pending_.end()) continue;
    const Pending g = it->second;
    pending_.erase(it);
    const GlobalExtrinsic& T = x.teammate(id);
    auto factor = std::make_unique<GravityAlignmentFactor>(
        g.g_in_Gj, Regularized<3>(g.covariance, 1e-12), options_.gravity_alignment_sigma_m_s2,
        T.R_Ga_Gb());
    const Eigen::Vector3d e = factor->Predict(x.ego, T);
    const Eigen::Matrix3d S = factor->covariance();
    if (gate->Add(std::move(factor), id, e, S)) {
      ++report->gravity;
      ++counters_->gravity_fused;
    }
  }
}

}  // namespace swarmlio::swarm::internal
