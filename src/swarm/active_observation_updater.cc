#include "active_observation_updater.h"

#include <cmath>
#include <memory>

#include "swarmlio/common/time.h"

#include "factors/active_observation_factor.h"
#include "innovation_noise_scale.h"
#include "observation_terms.h"

namespace swarmlio::swarm::internal {

void ActiveObservationUpdater::AddTerms(const UpdaterScan& scan, ObservationGate* gate,
                                        ScanReport* report) {
  const SwarmOptions& so = options_;
  if (!so.fuse_active || !scan.fusion_enabled) return;
  const SwarmState& x = *scan.x;
  const Eigen::Matrix3d R_Gi_bi = x.ego.R_G_b();
  Teammates& teammates = registry_->teammates();
  for (const teammate::TeammateObservation& o : *observations_) {
    const auto it = teammates.find(o.drone_id);
    if (!x.HasTeammate(o.drone_id) || it == teammates.end() || !it->second.have_message) {
      continue;
    }
    const net::EgoStateMessage& m = it->second.last;
    if (scan.skip_degenerate && m.degenerated) {
      ++report->skipped_degenerate;
      continue;
    }
    const double age = ToSeconds(scan.t_k - m.stamp_ns);
    if (std::abs(age) > so.max_message_age_s) {
      ++report->rejected;
      ++counters_->observations_rejected;
      continue;
    }
    const PredictedTeammate j = Predict(m, so.time_compensation ? age : 0.0);
    const GlobalExtrinsic& T = x.teammate(o.drone_id);
    const double share = ObservationShare(so, scan.previous_scan_degenerate, m.degenerated);
    TeammateInfo& info = it->second;
    const Eigen::Matrix3d R = info.observation_noise_scale * Regularized<3>(o.covariance_m2);
    auto factor = std::make_unique<ActiveObservationFactor>(
        o.p_bj_in_bi, j.p_bj_in_Gj, R / share, Regularized<3>(j.cov_p), R_Gi_bi, T.R_Ga_Gb());
    const Eigen::Vector3d e = factor->Predict(x.ego, T) - o.p_bj_in_bi;
    const Eigen::Matrix3d S = factor->covariance();
    if (so.noise_adaptation_rate > 0.0 && scan.P != nullptr && !gate->frozen()) {
      const double nis = ActiveObservationNis(*factor, x, *scan.P, o.drone_id, e, R / share, R);
      info.observation_noise_scale = UpdatedNoiseScale(info.observation_noise_scale, nis, so);
    }
    if (gate->Add(std::move(factor), o.drone_id, e, S)) {
      ++report->active;
      ++report->fused_by_teammate[o.drone_id].first;
      ++counters_->active_fused;
      if (!gate->frozen()) ++info.observations_fused;
    }
  }
}

}  // namespace swarmlio::swarm::internal
