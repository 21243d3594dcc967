#include "passive_observation_updater.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "swarmlio/common/time.h"

#include "factors/passive_observation_factor.h"
#include "observation_terms.h"

namespace swarmlio::swarm::internal {

void PassiveObservationUpdater::ForgetSender(int sender) {
  pending_.erase(std::remove_if(pending_.begin(), pending_.end(),
                                [&](const PendingPassive& p) { return p.from == sender; }),
                 pending_.end());
}

void PassiveObservationUpdater::AddTerms(const UpdaterScan& scan, ObservationGate* gate,
                                         ScanReport* report) {
  const SwarmOptions& so = options_;
  // The own track for the time compensation of passive observations.
  dead_reckoning_.Append(*scan.poses, so.max_message_age_s + 0.5);
  if (!so.fuse_passive || !scan.fusion_enabled) {
    pending_.clear();
    return;
  }
  const SwarmState& x = *scan.x;
  for (const PendingPassive& p : pending_) {
    if (!x.HasTeammate(p.from)) continue;
    if (scan.skip_degenerate && p.sender.degenerated) {
      ++report->skipped_degenerate;
      continue;
    }
    const double dt = ToSeconds(p.stamp_ns - scan.t_k);
    if (std::abs(dt) > so.max_message_age_s) {
      ++report->rejected;
      ++counters_->observations_rejected;
      continue;
    }
    const GlobalExtrinsic& T = x.teammate(p.from);
    // Own position at t_j: p + v dt + A(R, b_a, g) with A the IMU part of
    // the motion (dead_reckoning.h) when the history covers t_j, else the
    // constant-velocity shift p + v dt.
    ImuRetrodiction retrodiction;
    // The observer fused the same measurement actively: this use takes its
    // share of the information (SwarmOptions::observation_information_share).
    const Eigen::Matrix3d Sigma_obs =
        Regularized<3>(p.cov) /
        ObservationShare(so, scan.previous_scan_degenerate, p.sender.degenerated);
    if (so.time_compensation) dead_reckoning_.Retrodiction(p.stamp_ns, scan.t_k, &retrodiction);
    auto factor = std::make_unique<PassiveObservationFactor>(
        p.p_bi_in_bj, so.time_compensation ? dt : 0.0,
        p.sender.q_Gj_bj.normalized().toRotationMatrix(), p.sender.p_bj_in_Gj, Sigma_obs,
        Regularized<3>(p.sender.cov_theta_Gj_bj, 1e-10), Regularized<3>(p.sender.cov_p_bj_in_Gj),
        x.ego, T, retrodiction);
    const Eigen::Vector3d e = factor->Predict(x.ego, T) - p.p_bi_in_bj;
    const Eigen::Matrix3d S = factor->covariance();
    if (gate->Add(std::move(factor), p.from, e, S)) {
      ++report->passive;
      ++report->fused_by_teammate[p.from].second;
      if (!gate->frozen()) ++registry_->teammates()[p.from].observations_fused;
      ++counters_->passive_fused;
      if (p.repeated) ++counters_->passive_repeated;
    }
  }
  pending_.clear();  // each passive observation is used in one update at most
}

}  // namespace swarmlio::swarm::internal
