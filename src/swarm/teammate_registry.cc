#include "teammate_registry.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "swarmlio/common/time.h"

#include "observation_terms.h"

namespace swarmlio::swarm::internal {
namespace {

IdentificationEvent Event(int id, int64_t t_k, const char* method, const GlobalExtrinsic& T) {
  IdentificationEvent event;
  event.drone_id = id;
  event.stamp_ns = t_k;
  event.method = method;
  event.initial_T_Gi_Gj = T;
  return event;
}

// At least the covariance of an own match with zero residual.
void ApplySigmaFloors(const SwarmOptions& so, Eigen::Matrix<double, 6, 6>* C) {
  for (int k = 0; k < 3; ++k) {
    (*C)(k, k) =
        std::max((*C)(k, k), so.init_rotation_sigma_floor_rad * so.init_rotation_sigma_floor_rad);
    (*C)(3 + k, 3 + k) = std::max((*C)(3 + k, 3 + k), so.init_translation_sigma_floor_m *
                                                           so.init_translation_sigma_floor_m);
  }
}

// k's derived block came through teammate j (j is in its chain).
bool CameThrough(const TeammateInfo& info_k, int j) {
  return info_k.derived_through.count(j) > 0;
}

}  // namespace

void TeammateRegistry::UpdateBlocks(int64_t t_k, const teammate::ScanResult& detection,
                                    SwarmState* x, Eigen::MatrixXd* P, ScanReport* report,
                                    DroneEstimatorCounters* counters) {
  const size_t identified_before = report->identifications.size();
  const size_t removed_before = report->removed.size();
  AddMatched(t_k, detection, x, P, report);
  // Mutual identification: j matched this drone's trajectory and sent T_Gj_Gi.
  if (options_.mutual_identification) AddMutual(t_k, x, P, report);
  mutual_.clear();
  // Identification through teammates: k, identified by a known teammate j
  // (its own match T_Gj_Gk), enters as T_Gi_Gj T_Gj_Gk with the covariance
  // and the cross-covariances it inherits from the T_Gi_Gj block (it is a
  // function of it). Among several such j, the smallest composed covariance.
  if (options_.graph_identification) AddThroughTeammates(t_k, x, P, report);
  for (const teammate::TeammateObservation& o : detection.observations) {
    teammates_[o.drone_id].last_seen_ns = t_k;
  }
  RemoveLost(t_k, x, P, report);
  counters->identifications +=
      static_cast<int64_t>(report->identifications.size() - identified_before);
  counters->teammates_removed += static_cast<int64_t>(report->removed.size() - removed_before);
}

void TeammateRegistry::AddBlock(int id, int64_t t_k, const GlobalExtrinsic& T,
                                const Eigen::Matrix<double, 6, 6>& C, SwarmState* x,
                                Eigen::MatrixXd* P) {
  x->AddTeammate(id, T);
  AppendCovarianceBlock(C, P);
  teammates_[id].last_seen_ns = t_k;
}

bool TeammateRegistry::FollowsSource(int id) const {
  const auto it = teammates_.find(id);
  return it != teammates_.end() && it->second.second_hand &&
         it->second.observations_fused < options_.follow_source_until_observations;
}

void TeammateRegistry::ReplaceBlock(int id, const GlobalExtrinsic& T,
                                    const Eigen::Matrix<double, 6, 6>& C,
                                    const Eigen::MatrixXd& cross, SwarmState* x,
                                    Eigen::MatrixXd* P) {
  x->teammate(id) = T;
  const Segment b = x->layout().TeammateBlock(id);
  P->middleRows(b.offset, 6) = cross;
  P->middleCols(b.offset, 6) = cross.transpose();
  P->block<6, 6>(b.offset, b.offset) = C;
}

void TeammateRegistry::AddMatched(int64_t t_k, const teammate::ScanResult& detection,
                                  SwarmState* x, Eigen::MatrixXd* P, ScanReport* report) {
  const SwarmOptions& so = options_;
  for (const teammate::TeammateIdentification& id : detection.identifications) {
    if (x->HasTeammate(id.drone_id)) continue;
    GlobalExtrinsic T_Gi_Gj;
    T_Gi_Gj.q_Ga_Gb = Eigen::Quaterniond(id.R_Gi_Gj).normalized();
    T_Gi_Gj.p_Gb_in_Ga = id.p_Gj_in_Gi;
    const double sigma_p = std::max(so.init_translation_sigma_floor_m,
                                    so.init_translation_sigma_per_residual * id.mean_residual_m);
    // The excitation flights span about a metre: a translation error sigma_p
    // at the ends of a 1 m lever is a rotation error of sigma_p rad.
    const double sigma_r = std::max(so.init_rotation_sigma_floor_rad, sigma_p / 1.0);
    Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
    C.diagonal().head<3>().setConstant(sigma_r * sigma_r);
    C.diagonal().tail<3>().setConstant(sigma_p * sigma_p);
    AddBlock(id.drone_id, t_k, T_Gi_Gj, C, x, P);
    SetProvenance(false, false, {}, &teammates_[id.drone_id]);
    IdentificationEvent event = Event(id.drone_id, t_k, "trajectory_match", T_Gi_Gj);
    event.mean_residual_m = id.mean_residual_m;
    report->identifications.push_back(event);
  }
}

void TeammateRegistry::AddMutual(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P,
                                 ScanReport* report) {
  for (const auto& [j, pending] : mutual_) {
    if (teammates_[j].restarted) continue;
    const bool follow = x->HasTeammate(j) && !teammates_[j].via_graph && FollowsSource(j);
    if (x->HasTeammate(j) && !follow) continue;
    GlobalExtrinsic T_Gi_Gj;
    Eigen::Matrix<double, 6, 6> C;
    InvertExtrinsic(pending.T_Gj_Gi, pending.cov_T_Gj_Gi, &T_Gi_Gj, &C);
    // Positive definite whatever arrived, and at least the covariance of an
    // own match with zero residual.
    C = Regularized<6>(C, 1e-10);
    ApplySigmaFloors(options_, &C);
    if (follow) {
      // j's newer estimate of the same edge, independent of this drone's state.
      ReplaceBlock(j, T_Gi_Gj, C, Eigen::MatrixXd::Zero(6, P->rows()), x, P);
      continue;
    }
    if (!detector_->AddIdentifiedTeammate(j, t_k, T_Gi_Gj.R_Ga_Gb(), T_Gi_Gj.p_Gb_in_Ga)) continue;
    AddBlock(j, t_k, T_Gi_Gj, C, x, P);
    // The inverse of an edge j derived itself stays derived, through
    // teammates j did not name: any teammate heard so far may be in its chain.
    const bool derived = pending.source == net::ExtrinsicSource::kGraph;
    SetProvenance(true, derived, derived ? HeardTeammates(teammates_, j) : std::map<int, int64_t>(),
                  &teammates_[j]);
    report->identifications.push_back(Event(j, t_k, "teammate_match", T_Gi_Gj));
  }
}

void TeammateRegistry::AddThroughTeammates(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P,
                                           ScanReport* report) {
  struct Candidate {
    GlobalExtrinsic T_Gi_Gk;
    Eigen::Matrix<double, 6, 6> J_ij;
    Eigen::Matrix<double, 6, 6> C;  // J_ij P_ij J_ij^T + J_jk C_jk J_jk^T
    int via = -1;
  };
  std::map<int, Candidate> best;  // by k
  for (int j : x->layout().teammate_ids()) {
    const TeammateInfo& info_j = teammates_[j];
    // Only j's first-hand edges (identified), and only through a derived j
    // that no longer leans on the teammates it came through.
    if (!CanRelay(info_j, *x, teammates_, options_)) continue;
    const Segment bj = x->layout().TeammateBlock(j);
    const Eigen::Matrix<double, 6, 6> P_ij = P->block<6, 6>(bj.offset, bj.offset);
    for (const auto& [k, match] : info_j.identified) {
      if (k == self_id_ || k == j) continue;
      // A block k already holds follows a new composition while it has
      // little of its own, and only through the teammate it came through.
      if (x->HasTeammate(k) &&
          !(teammates_[k].via_graph && FollowsSource(k) && CameThrough(teammates_[k], j))) {
        continue;
      }
      if (ChainPassesThrough(info_j, k, teammates_)) continue;
      const auto it_k = teammates_.find(k);
      if (it_k != teammates_.end() && it_k->second.restarted) continue;
      Candidate c;
      Eigen::Matrix<double, 6, 6> J_jk;
      ComposeExtrinsic(x->teammate(j), match.T_Gj_Gk, &c.T_Gi_Gk, &c.J_ij, &J_jk);
      const Eigen::Matrix<double, 6, 6> C_jk = Regularized<6>(match.cov_T_Gj_Gk, 1e-10);
      c.C = c.J_ij * P_ij * c.J_ij.transpose() + J_jk * C_jk * J_jk.transpose();
      c.via = j;
      const auto it = best.find(k);
      if (it == best.end() || c.C.trace() < it->second.C.trace()) best[k] = c;
    }
  }
  for (const auto& [k, c] : best) {
    // Cross-covariances: d(T_ik) = J_ij d(T_ij) + J_jk d(T_jk) with d(T_jk)
    // independent of this drone's state, so P(k, :) = J_ij P(j, :).
    const Segment bj = x->layout().TeammateBlock(c.via);
    Eigen::MatrixXd cross = c.J_ij * P->middleRows(bj.offset, 6);
    Eigen::Matrix<double, 6, 6> C = 0.5 * (c.C + c.C.transpose());
    ApplySigmaFloors(options_, &C);
    if (x->HasTeammate(k)) {
      const Segment bk = x->layout().TeammateBlock(k);
      cross.middleCols(bk.offset, 6).setZero();  // its own block: C
      ReplaceBlock(k, c.T_Gi_Gk, C, cross, x, P);
      continue;
    }
    if (!detector_->AddIdentifiedTeammate(k, t_k, c.T_Gi_Gk.R_Ga_Gb(), c.T_Gi_Gk.p_Gb_in_Ga)) {
      continue;
    }
    const int n = static_cast<int>(P->rows());
    AddBlock(k, t_k, c.T_Gi_Gk, C, x, P);
    P->block(n, 0, 6, n) = cross;
    P->block(0, n, n, 6) = cross.transpose();
    // k's chain: j's (empty when j is first-hand) and j itself.
    std::map<int, int64_t> through = teammates_[c.via].derived_through;
    through[c.via] = teammates_[c.via].session_start_ns;
    SetProvenance(true, true, std::move(through), &teammates_[k]);
    IdentificationEvent event = Event(k, t_k, "graph", c.T_Gi_Gk);
    event.via_drone_id = c.via;
    report->identifications.push_back(event);
  }
}

void TeammateRegistry::RemoveLost(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P,
                                  ScanReport* report) {
  const std::vector<int> ids = x->layout().teammate_ids();
  for (int id : ids) {
    TeammateInfo& info = teammates_[id];
    const int64_t last = std::max(info.last_seen_ns, info.last_heard_ns);
    const bool lost = ToSeconds(t_k - last) > options_.teammate_timeout_s;
    if (!lost && !info.restarted) continue;
    EraseCovarianceBlock(x->layout().TeammateBlock(id), P);
    x->RemoveTeammate(id);
    if (lost) detector_->ForgetTeammate(id);
    info.restarted = false;
    report->removed.push_back(id);
  }
}

}  // namespace swarmlio::swarm::internal

namespace swarmlio::swarm::internal {

std::vector<TeammateEstimate> TeammateRegistry::Estimates(int64_t t_k, const SwarmState& x,
                                                          const Eigen::MatrixXd& P,
                                                          const ScanReport& report) {
  std::vector<TeammateEstimate> estimates;
  for (int id : x.layout().teammate_ids()) {
    TeammateEstimate e;
    e.drone_id = id;
    e.T_Gi_Gj = x.teammate(id);
    const Segment block = x.layout().TeammateBlock(id);
    e.extrinsic_covariance = P.block<6, 6>(block.offset, block.offset);
    const TeammateInfo& info = teammates_[id];
    if (info.have_message &&
        std::abs(ToSeconds(t_k - info.last.stamp_ns)) <= options_.max_message_age_s) {
      const PredictedTeammate j = Predict(info.last, ToSeconds(t_k - info.last.stamp_ns));
      const Eigen::Matrix3d R_Gi_Gj = e.T_Gi_Gj.R_Ga_Gb();
      e.have_pose = true;
      e.q_Gi_bj = Eigen::Quaterniond(R_Gi_Gj * j.R_Gj_bj).normalized();
      e.p_bj_in_Gi = R_Gi_Gj * j.p_bj_in_Gj + e.T_Gi_Gj.p_Gb_in_Ga;
      e.v_bj_in_Gi = R_Gi_Gj * j.v_bj_in_Gj;
    }
    e.seen = info.last_seen_ns == t_k;
    const auto fused = report.fused_by_teammate.find(id);
    if (fused != report.fused_by_teammate.end()) {
      e.active_observations = fused->second.first;
      e.passive_observations = fused->second.second;
    }
    estimates.push_back(e);
  }
  return estimates;
}

}  // namespace swarmlio::swarm::internal
