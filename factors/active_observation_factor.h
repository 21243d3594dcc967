// ActiveObservationFactor: drone i (the ego) observes teammate j's body origin
// (paper Sec. III-D, mutual observation, "active" case; docs/factors.md).
//
// Parameter blocks (ambient): ego (19) = [q_Gi_bi (x y z w) | p | v | b_g | b_a | g],
// teammate extrinsic (7) = [q_Gi_Gj (x y z w) | p_Gj_in_Gi].
// Constants: the measurement z = p_bj_in_bi (in b_i [m]) and the teammate's
// position p_bj_in_Gj (in its own global frame G_j, already predicted to the
// update time by the caller).
//
//   h = R_Gi_bi^T (R_Gi_Gj p_bj_in_Gj + p_Gj_in_Gi - p_bi_in_Gi)
//   r = U^-1 (h - z),   S = U U^T (lower Cholesky),   |r|^2 = (h - z)^T S^-1 (h - z)
//
// Noise, evaluated ONCE at construction at the linearization rotations
// (R_Gi_bi, R_Gi_Gj) given to the constructor:
//   S = Sigma_obs + A Sigma_p_bj_in_Gj A^T,   A = dh/dp_bj_in_Gj = R_Gi_bi^T R_Gi_Gj
// (Sigma_obs: detection covariance in b_i; Sigma_p_bj_in_Gj: the teammate's
// broadcast position covariance in G_j).
//
// Tangent Jacobian of h (right perturbation R Exp(dtheta), p + dp; ego in
// ErrorStateLayout order [dtheta dp dv dbg dba dg], extrinsic [dphi dp]):
//   dh/d dtheta_ego = [h]x                  ((R Exp(d))^T u = (I - [d]x) R^T u)
//   dh/d dp_ego     = -R_Gi_bi^T
//   dh/d dphi_ext   = -R_Gi_bi^T R_Gi_Gj [p_bj_in_Gj]x
//   dh/d dp_ext     =  R_Gi_bi^T
//   zero for v, b_g, b_a, g.
// The residual Jacobian is U^-1 times these. Rotation columns are lifted to
// the quaternions' ambient coordinates with SO3Manifold::LiftTangentJacobian.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

class ActiveObservationFactor final
    : public ceres::SizedCostFunction<3, EgoState::kAmbientSize, GlobalExtrinsic::kAmbientSize> {
 public:
  /// z = p_bj_in_bi [m]; Sigma_obs [m^2] in b_i; Sigma_p_bj_in_Gj [m^2] in G_j.
  /// R_Gi_bi and R_Gi_Gj are the linearization rotations at which S is
  /// evaluated. S must be positive definite (CHECK); it is symmetrized first.
  ActiveObservationFactor(const Eigen::Vector3d& p_bj_in_bi,
                          const Eigen::Vector3d& p_bj_in_Gj,
                          const Eigen::Matrix3d& Sigma_obs,
                          const Eigen::Matrix3d& Sigma_p_bj_in_Gj,
                          const Eigen::Matrix3d& R_Gi_bi,
                          const Eigen::Matrix3d& R_Gi_Gj);

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// The prediction h (unwhitened) [m].
  Eigen::Vector3d Predict(const EgoState& ego, const GlobalExtrinsic& extrinsic) const;
  /// The whitened residual r = U^-1 (h - z).
  Eigen::Vector3d Residual(const EgoState& ego, const GlobalExtrinsic& extrinsic) const;
  /// Whitened tangent Jacobians dr/d dx_ego (3x18) and dr/d dx_ext (3x6).
  /// Either pointer may be nullptr.
  void TangentJacobian(const EgoState& ego,
                       const GlobalExtrinsic& extrinsic,
                       Eigen::Matrix<double, 3, EgoState::kTangentSize>* J_ego,
                       Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize>* J_ext) const;

  const Eigen::Vector3d& measurement() const { return p_bj_in_bi_; }
  /// S, the innovation covariance of h - z [m^2].
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  /// U^-1 (lower triangular), with S = U U^T.
  const Eigen::Matrix3d& sqrt_information() const { return sqrt_information_; }

 private:
  Eigen::Vector3d p_bj_in_bi_;
  Eigen::Vector3d p_bj_in_Gj_;
  Eigen::Matrix3d covariance_;
  Eigen::Matrix3d sqrt_information_;
};

}  // namespace swarmlio
