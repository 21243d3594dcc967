#include "teammate_state.h"

#include "swarmlio/math/so3.h"

namespace swarmlio::swarm::internal {

bool Finite(const net::EgoStateMessage& m) {
  return m.q_Gj_bj.coeffs().allFinite() && m.p_bj_in_Gj.allFinite() && m.v_bj_in_Gj.allFinite() &&
         m.omega_bj_in_bj.allFinite() && m.cov_theta_Gj_bj.allFinite() &&
         m.cov_p_bj_in_Gj.allFinite() && m.cov_v_bj_in_Gj.allFinite();
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
  const Eigen::Matrix3d R_ij = T_ij.R_Gi_Gj();
  const Eigen::Matrix3d R_jk = T_jk.R_Gi_Gj();
  T_ik->q_Gi_Gj = (T_ij.q_Gi_Gj.normalized() * T_jk.q_Gi_Gj.normalized()).normalized();
  T_ik->p_Gj_in_Gi = R_ij * T_jk.p_Gj_in_Gi + T_ij.p_Gj_in_Gi;
  J_ij->setZero();
  J_ij->topLeftCorner<3, 3>() = R_jk.transpose();
  J_ij->bottomLeftCorner<3, 3>() = -R_ij * so3::Hat(T_jk.p_Gj_in_Gi);
  J_ij->bottomRightCorner<3, 3>().setIdentity();
  J_jk->setZero();
  J_jk->topLeftCorner<3, 3>().setIdentity();
  J_jk->bottomRightCorner<3, 3>() = R_ij;
}

void InvertExtrinsic(const net::GlobalExtrinsicEntry& e, GlobalExtrinsic* T,
                     Eigen::Matrix<double, 6, 6>* C) {
  const Eigen::Matrix3d R = e.q_Gi_Gj.normalized().toRotationMatrix();
  T->q_Gi_Gj = e.q_Gi_Gj.normalized().conjugate();
  T->p_Gj_in_Gi = -(R.transpose() * e.p_Gj_in_Gi);
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
  J.topLeftCorner<3, 3>() = -R;
  J.bottomLeftCorner<3, 3>() = so3::Hat(T->p_Gj_in_Gi);
  J.bottomRightCorner<3, 3>() = -R.transpose();
  *C = J * e.covariance * J.transpose();
}

}  // namespace swarmlio::swarm::internal
