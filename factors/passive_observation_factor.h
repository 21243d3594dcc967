// PassiveObservationFactor: teammate j observed drone i (the ego) and
// broadcast the detection (paper Sec. III-D, mutual observation, "passive"
// case; docs/factors.md).
//
// Parameter blocks (ambient): ego (19) = [q_Gi_bi (x y z w) | p | v | b_g | b_a | g],
// teammate extrinsic (7) = [q_Gi_Gj (x y z w) | p_Gj_in_Gi].
// Constants: the measurement z = p_bi_in_bj (in b_j [m]) taken by j at time
// t_j (already in i's clock), the teammate's broadcast pose at t_j
// (R_Gj_bj, p_bj_in_Gj), dt = t_j - t_k [s] where t_k is the time of the
// ego state, and the IMU retrodiction (W, u, M) of the own motion over
// [t_j, t_k] (ImuRetrodiction below; all zero: constant velocity). The ego
// position at t_j is a function of the state at t_k:
//
//   p(t_j) = p + v dt + A,   A = R (u + M (b_a0 - b_a)) + W g
//   w = R_Gi_Gj^T (p(t_j) - p_Gj_in_Gi)                    (ego position at t_j in G_j)
//   h = R_Gj_bj^T (w - p_bj_in_Gj)
//   r = U^-1 (h - z),   S = U U^T (lower Cholesky),   |r|^2 = (h - z)^T S^-1 (h - z)
//
// A is the double integral of the kinematic acceleration R(s)(f(s) - b_a) + g
// from t_j to t_k with weight (s - t_j): W = int (s - t_j) ds = dt^2 / 2,
// u = R0^T (int (s - t_j) a(s) ds - W g0) and M = R0^T int (s - t_j) R(s) ds,
// formed at the linearization state (R0, b_a0, g0); at that state A equals
// the integrated propagated acceleration. Through A the observation of the
// past position also informs attitude, accelerometer bias and gravity (a
// delayed observation modelled with p and v only fed the bias's effect into
// the velocity and diverged beyond 0.3 s of latency; docs/swarm.md).
//
// Noise, evaluated ONCE at construction at the linearization point (the ego
// state and extrinsic given to the constructor, through h0 = h(lin)):
//   S = Sigma_obs + [h0]x Sigma_theta_bj [h0]x^T + R_Gj_bj^T Sigma_p_bj_in_Gj R_Gj_bj
// with Sigma_obs the detection covariance in b_j, and Sigma_theta_bj,
// Sigma_p_bj_in_Gj j's broadcast attitude (right perturbation
// R_Gj_bj Exp(dtheta)) and position covariances; dh/d dtheta_bj = [h]x and
// dh/d dp_bj = -R_Gj_bj^T.
//
// Tangent Jacobian of h (right perturbation R Exp(dtheta), p + dp; ego in
// ErrorStateLayout order [dtheta dp dv dbg dba dg], extrinsic [dphi dp]),
// with M_h = R_Gj_bj^T R_Gi_Gj^T and c = u + M (b_a0 - b_a):
//   dh/d dtheta_ego = -M_h R [c]x           (R Exp(e) c = R c - R [c]x e)
//   dh/d dp_ego     = M_h
//   dh/d dv_ego     = M_h dt
//   dh/d dbg_ego    = 0
//   dh/d dba_ego    = -M_h R M
//   dh/d dg_ego     = M_h W
//   dh/d dphi_ext   = R_Gj_bj^T [w]x        ((R Exp(f))^T u = (I - [f]x) R^T u)
//   dh/d dp_ext     = -M_h
// The residual Jacobian is U^-1 times these. Rotation columns are lifted to
// the quaternions' ambient coordinates with SO3Manifold::LiftTangentJacobian.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

/// The own IMU motion over [t_j, t_k] in G_i, integrals with the weight
/// (s - t_j) (from the propagated poses; src/swarm/dead_reckoning.h). All
/// zero: no history (the factor then moves the ego with constant velocity).
struct ImuRetrodiction {
  double weight_s2 = 0.0;                                         // W = int (s - t_j) ds [s^2]
  Eigen::Vector3d weighted_acc_in_G = Eigen::Vector3d::Zero();    // int (s - t_j) a(s) ds [m]
  Eigen::Matrix3d weighted_R_G_b = Eigen::Matrix3d::Zero();       // int (s - t_j) R_G_b(s) ds [s^2]
};

class PassiveObservationFactor final
    : public ceres::SizedCostFunction<3, EgoState::kAmbientSize, GlobalExtrinsic::kAmbientSize> {
 public:
  /// z = p_bi_in_bj [m]; dt = t_j - t_k [s]; (R_Gj_bj, p_bj_in_Gj) is j's pose
  /// at t_j; Sigma_obs [m^2] in b_j, Sigma_theta_bj [rad^2], Sigma_p_bj_in_Gj
  /// [m^2] in G_j. S is evaluated at h0 = h(ego_lin, extrinsic_lin). S must be
  /// positive definite (CHECK); it is symmetrized first.
  PassiveObservationFactor(const Eigen::Vector3d& p_bi_in_bj,
                           double dt,
                           const Eigen::Matrix3d& R_Gj_bj,
                           const Eigen::Vector3d& p_bj_in_Gj,
                           const Eigen::Matrix3d& Sigma_obs,
                           const Eigen::Matrix3d& Sigma_theta_bj,
                           const Eigen::Matrix3d& Sigma_p_bj_in_Gj,
                           const EgoState& ego_lin,
                           const GlobalExtrinsic& extrinsic_lin,
                           const ImuRetrodiction& retrodiction = ImuRetrodiction());

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

  const Eigen::Vector3d& measurement() const { return p_bi_in_bj_; }
  double dt() const { return dt_; }
  /// S, the innovation covariance of h - z [m^2].
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  /// U^-1 (lower triangular), with S = U U^T.
  const Eigen::Matrix3d& sqrt_information() const { return sqrt_information_; }

 private:
  // c = u + M (b_a0 - b_a) and A = R c + W g.
  Eigen::Vector3d C(const EgoState& ego) const;
  // w = R_Gi_Gj^T (p + v dt + A - p_Gj_in_Gi), the ego position at t_j in G_j.
  Eigen::Vector3d EgoPositionInGj(const EgoState& ego, const GlobalExtrinsic& extrinsic) const;

  Eigen::Vector3d p_bi_in_bj_;
  double dt_;
  double W_;            // [s^2]
  Eigen::Vector3d u_;   // [m]
  Eigen::Matrix3d M_;   // [s^2]
  Eigen::Vector3d accel_bias_lin_;
  Eigen::Matrix3d R_Gj_bj_;
  Eigen::Vector3d p_bj_in_Gj_;
  Eigen::Matrix3d covariance_;
  Eigen::Matrix3d sqrt_information_;
};

}  // namespace swarmlio
