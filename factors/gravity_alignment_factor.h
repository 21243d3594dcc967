// GravityAlignmentFactor: drone i's and teammate j's global frames see the
// same gravity (docs/swarm.md, "Gravity alignment"; not in the paper).
//
// Each drone's global frame G is its IMU frame at initialization, not
// gravity aligned; gravity g_in_G is part of its state (ErrorStateLayout).
// Both drones fly in the same gravity field, so T_Gi_Gj must map j's gravity
// onto i's:  R_Gi_Gj g_in_Gj = g_in_Gi. This fixes the two tilt degrees of
// freedom of R_Gi_Gj, which the mutual observations of drones flying at
// similar heights determine only weakly (a tilt moves a teammate a metre
// away by its sine, a few millimetres).
//
// Parameter blocks (ambient): ego (19) = [q_Gi_bi | p | v | b_g | b_a | g_in_Gi],
// teammate extrinsic (7) = [q_Gi_Gj (x y z w) | p_Gj_in_Gi].
// Constant: g_in_Gj, teammate j's broadcast gravity estimate [m/s^2].
//
//   h = R_Gi_Gj g_in_Gj - g_in_Gi                       (z = 0)
//   r = U^-1 h,   S = U U^T (lower Cholesky),   |r|^2 = h^T S^-1 h
//   S = R_Gi_Gj Sigma_g_in_Gj R_Gi_Gj^T + sigma_floor^2 I
// evaluated once at construction at the linearization rotation R_Gi_Gj
// (Sigma_g_in_Gj: j's broadcast gravity covariance; sigma_floor: the
// caller's allowance for j's gravity error being correlated over time, as
// the same estimate is fused again with every broadcast).
//
// Tangent Jacobian of h (right perturbation R Exp(dphi); ego in
// ErrorStateLayout order [dtheta dp dv dbg dba dg], extrinsic [dphi dp]):
//   dh/d dg_ego    = -I
//   dh/d dphi_ext  = -R_Gi_Gj [g_in_Gj]x      (R Exp(d) u = R (u + d x u))
//   zero for every other column.
// The residual Jacobian is U^-1 times these.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

class GravityAlignmentFactor final
    : public ceres::SizedCostFunction<3, EgoState::kAmbientSize, GlobalExtrinsic::kAmbientSize> {
 public:
  /// g_in_Gj [m/s^2] with Sigma_g_in_Gj [m^2/s^4] (in G_j); sigma_floor_m_s2
  /// >= 0 [m/s^2]; R_Gi_Gj: the linearization rotation at which S is
  /// evaluated. S must be positive definite (CHECK); it is symmetrized first.
  GravityAlignmentFactor(const Eigen::Vector3d& g_in_Gj, const Eigen::Matrix3d& Sigma_g_in_Gj,
                         double sigma_floor_m_s2, const Eigen::Matrix3d& R_Gi_Gj);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The prediction h (unwhitened) [m/s^2]; the measurement is zero.
  Eigen::Vector3d Predict(const EgoState& ego, const GlobalExtrinsic& extrinsic) const;
  /// The whitened residual r = U^-1 h.
  Eigen::Vector3d Residual(const EgoState& ego, const GlobalExtrinsic& extrinsic) const;
  /// Whitened tangent Jacobians dr/d dx_ego (3x18) and dr/d dx_ext (3x6).
  /// Either pointer may be nullptr.
  void TangentJacobian(const EgoState& ego, const GlobalExtrinsic& extrinsic,
                       Eigen::Matrix<double, 3, EgoState::kTangentSize>* J_ego,
                       Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize>* J_ext) const;

  /// S, the covariance of h [m^2/s^4].
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  const Eigen::Matrix3d& sqrt_information() const { return sqrt_information_; }

 private:
  Eigen::Vector3d g_in_Gj_;
  Eigen::Matrix3d covariance_;
  Eigen::Matrix3d sqrt_information_;
};

}  // namespace swarmlio
