#include "teammate_state.h"

#include <utility>

#include "swarmlio/math/so3.h"

namespace swarmlio::swarm::internal {

bool Finite(const net::EgoStateMessage& m) {
  return m.q_Gj_bj.coeffs().allFinite() && m.p_bj_in_Gj.allFinite() && m.v_bj_in_Gj.allFinite() &&
         m.omega_bj_in_bj.allFinite() && m.cov_theta_Gj_bj.allFinite() &&
         m.cov_p_bj_in_Gj.allFinite() && m.cov_v_bj_in_Gj.allFinite();
}

void SetProvenance(bool second_hand, bool via_graph, std::map<int, int64_t> derived_through,
                   TeammateInfo* info) {
  info->second_hand = second_hand;
  info->via_graph = via_graph;
  info->derived_through = std::move(derived_through);
  info->observations_fused = 0;
}

int64_t SessionOf(const Teammates& teammates, int id) {
  const auto it = teammates.find(id);
  return it == teammates.end() ? 0 : it->second.session_start_ns;
}

std::map<int, int64_t> HeardTeammates(const Teammates& teammates, int except) {
  std::map<int, int64_t> heard;
  for (const auto& [id, info] : teammates) {
    if (id != except && info.last_heard_ns > 0) heard[id] = info.session_start_ns;
  }
  return heard;
}

bool LeansOnTeammates(const TeammateInfo& info_j, const SwarmState& x, const Teammates& teammates) {
  for (const auto& [v, session] : info_j.derived_through) {
    if (x.HasTeammate(v) && SessionOf(teammates, v) == session) return true;
  }
  return false;
}

bool CanRelay(const TeammateInfo& info_j, const SwarmState& x, const Teammates& teammates,
              const SwarmOptions& options) {
  if (!info_j.via_graph) return true;
  if (!options.graph_through_derived) return false;
  // Once the teammates it came through left (or restarted), its block is the
  // only link to j's side of the swarm, with the correlations the
  // composition gave it; own observations of j make it first-hand-like.
  return !LeansOnTeammates(info_j, x, teammates) ||
         info_j.observations_fused >= options.graph_derived_min_observations;
}

bool ChainPassesThrough(const TeammateInfo& info_j, int k, const Teammates& teammates) {
  const auto it = info_j.derived_through.find(k);
  return it != info_j.derived_through.end() && it->second == SessionOf(teammates, k);
}

PredictedTeammate Predict(const net::EgoStateMessage& m, double dt) {
  PredictedTeammate out;
  const Eigen::Matrix3d R = m.q_Gj_bj.normalized().toRotationMatrix();
  out.R_Gj_bj = R * so3::Exp(m.omega_bj_in_bj * dt);
  out.p_bj_in_Gj = m.p_bj_in_Gj + m.v_bj_in_Gj * dt;
  out.v_bj_in_Gj = m.v_bj_in_Gj;
  out.cov_p = m.cov_p_bj_in_Gj + dt * dt * m.cov_v_bj_in_Gj;
  out.cov_theta = m.cov_theta_Gj_bj;
  return out;
}

void ComposeExtrinsic(const GlobalExtrinsic& T_ij, const GlobalExtrinsic& T_jk, GlobalExtrinsic* T_ik,
                      Eigen::Matrix<double, 6, 6>* J_ij, Eigen::Matrix<double, 6, 6>* J_jk) {
  const Eigen::Matrix3d R_ij = T_ij.R_Ga_Gb();
  const Eigen::Matrix3d R_jk = T_jk.R_Ga_Gb();
  T_ik->q_Ga_Gb = (T_ij.q_Ga_Gb.normalized() * T_jk.q_Ga_Gb.normalized()).normalized();
  T_ik->p_Gb_in_Ga = R_ij * T_jk.p_Gb_in_Ga + T_ij.p_Gb_in_Ga;
  J_ij->setZero();
  J_ij->topLeftCorner<3, 3>() = R_jk.transpose();
  J_ij->bottomLeftCorner<3, 3>() = -R_ij * so3::Hat(T_jk.p_Gb_in_Ga);
  J_ij->bottomRightCorner<3, 3>().setIdentity();
  J_jk->setZero();
  J_jk->topLeftCorner<3, 3>().setIdentity();
  J_jk->bottomRightCorner<3, 3>() = R_ij;
}

void InvertExtrinsic(const GlobalExtrinsic& T_Gj_Gi,
                     const Eigen::Matrix<double, 6, 6>& cov_T_Gj_Gi,
                     GlobalExtrinsic* T_Gi_Gj,
                     Eigen::Matrix<double, 6, 6>* cov_T_Gi_Gj) {
  const Eigen::Matrix3d R = T_Gj_Gi.R_Ga_Gb();  // R_Gj_Gi
  T_Gi_Gj->q_Ga_Gb = T_Gj_Gi.q_Ga_Gb.conjugate();
  T_Gi_Gj->p_Gb_in_Ga = -(R.transpose() * T_Gj_Gi.p_Gb_in_Ga);
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
  J.topLeftCorner<3, 3>() = -R;
  J.bottomLeftCorner<3, 3>() = so3::Hat(T_Gi_Gj->p_Gb_in_Ga);
  J.bottomRightCorner<3, 3>() = -R.transpose();
  *cov_T_Gi_Gj = J * cov_T_Gj_Gi * J.transpose();
}

}  // namespace swarmlio::swarm::internal
