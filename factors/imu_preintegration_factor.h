// ImuPreintegrationFactor: the IMU between two consecutive scan states of the
// fixed-lag window, as one 18-dim residual over (ego_k, ego_k+1) (on-manifold
// preintegration, Forster et al., T-RO 2017; docs/factors.md, "IMU
// preintegration factor"; the discrete model is ImuPropagator's, docs/imu.md).
//
// Parameter blocks (ambient): ego_k, ego_k+1 (19 each) = [q_G_b (x y z w) | p |
// v | b_g | b_a | g]. Constants (PreintegratedImu, built by
// swarmlio::lio::ImuPreintegration from the samples in [t_k, t_k+1]): T = t_k+1 - t_k,
// DeltaR, Deltav, Deltap (in b_k, gravity excluded) at the linearization biases
// (bg_bar, ba_bar), their bias Jacobians, and the covariance Sigma (18x18).
//
// First-order bias correction (dbg = bg_k - bg_bar, dba = ba_k - ba_bar, c = J^R_g dbg):
//   DeltaR_c = DeltaR Exp(c)
//   Deltav_c = Deltav + J^v_g dbg + J^v_a dba
//   Deltap_c = Deltap + J^p_g dbg + J^p_a dba
//
// Error e (ErrorStateLayout order [R p v bg ba g]) and residual:
//   E    = DeltaR_c^T R_k^T R_k+1,                  e_R  = Log(E)
//   d_p  = p_k+1 - p_k - v_k T - 1/2 g_k T^2,       e_p  = R_k^T d_p - Deltap_c
//   d_v  = v_k+1 - v_k - g_k T,                     e_v  = R_k^T d_v - Deltav_c
//   e_bg = bg_k+1 - bg_k,   e_ba = ba_k+1 - ba_k,   e_g  = g_k+1 - g_k
//   r = U^-1 e,   Sigma = U U^T (lower Cholesky),   |r|^2 = e^T Sigma^-1 e
//
// Sigma = blockdiag(P15, sigma_g^2 I3): P15 is the joint covariance of the
// preintegration errors (dtheta, dp, dv) and of the bias random walks over
// [t_k, t_k+1] (with their cross-covariance), propagated with the propagator's
// F and G from P = 0; sigma_g is a small floor (g is constant, g' = g, so its
// true process noise is zero and the matrix would be singular).
//
// Tangent Jacobian of e (right perturbation R Exp(dtheta), Euclidean parts
// add), Jr^-1 = Jr^-1(e_R); zero where not listed:
//   de_R/d dtheta_k   = -Jr^-1 R_k+1^T R_k          de_R/d dtheta_k+1 = Jr^-1
//   de_R/d dbg_k      = -Jr^-1 E^T Jr(c) J^R_g
//   de_p/d dtheta_k   = [R_k^T d_p]x                de_v/d dtheta_k   = [R_k^T d_v]x
//   de_p/d dp_k       = -R_k^T                      de_p/d dp_k+1     =  R_k^T
//   de_p/d dv_k       = -R_k^T T                    de_v/d dv_k       = -R_k^T
//   de_p/d dg_k       = -1/2 R_k^T T^2              de_v/d dv_k+1     =  R_k^T
//   de_p/d dbg_k      = -J^p_g                      de_v/d dg_k       = -R_k^T T
//   de_p/d dba_k      = -J^p_a                      de_v/d dbg_k      = -J^v_g
//                                                   de_v/d dba_k      = -J^v_a
//   de_bg, de_ba, de_g: -I on block k, +I on block k+1.
// The residual Jacobian is U^-1 times these. Rotation columns are lifted to
// the quaternions' ambient coordinates with SO3Manifold::LiftTangentJacobian.
//
// At e = 0 the linearization -(de/d dx_k+1)^-1 de/d dx_k is the propagator's
// accumulated F over [t_k, t_k+1], so a window of one state (a prior with the
// filter's P_k plus this factor) reproduces the filter's prediction: the
// mean exactly and the covariance up to the gravity floor.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <memory>

#include "swarmlio/common/status.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

/// The preintegrated IMU between t_k and t_k+1 (ImuPreintegration fills it).
/// Deltas are in the body frame b_k at t_k and exclude gravity:
///   R_k+1 = R_k DeltaR,  v_k+1 = v_k + g T + R_k Deltav,
///   p_k+1 = p_k + v_k T + 1/2 g T^2 + R_k Deltap.
struct PreintegratedImu {
  using Matrix18 = Eigen::Matrix<double, EgoState::kTangentSize, EgoState::kTangentSize>;

  double dt_s = 0.0;                                         // T [s]
  Eigen::Matrix3d delta_R = Eigen::Matrix3d::Identity();     // DeltaR = R_k^T R_k+1
  Eigen::Vector3d delta_v = Eigen::Vector3d::Zero();         // Deltav [m/s]
  Eigen::Vector3d delta_p = Eigen::Vector3d::Zero();         // Deltap [m]
  Eigen::Vector3d gyro_bias_lin = Eigen::Vector3d::Zero();   // bg_bar [rad/s]
  Eigen::Vector3d accel_bias_lin = Eigen::Vector3d::Zero();  // ba_bar [m/s^2]
  Eigen::Matrix3d dR_dbg = Eigen::Matrix3d::Zero();          // J^R_g [s]
  Eigen::Matrix3d dv_dbg = Eigen::Matrix3d::Zero();          // J^v_g [m/rad]
  Eigen::Matrix3d dv_dba = Eigen::Matrix3d::Zero();          // J^v_a [s]
  Eigen::Matrix3d dp_dbg = Eigen::Matrix3d::Zero();          // J^p_g [m s/rad]
  Eigen::Matrix3d dp_dba = Eigen::Matrix3d::Zero();          // J^p_a [s^2]
  /// Sigma, the covariance of e in ErrorStateLayout order (gravity floor included).
  Matrix18 covariance = Matrix18::Zero();

  /// DeltaR_c, Deltav_c, Deltap_c at biases (bg, ba) (first-order correction).
  Eigen::Matrix3d CorrectedDeltaR(const Eigen::Vector3d& gyro_bias) const;
  Eigen::Vector3d CorrectedDeltaV(const Eigen::Vector3d& gyro_bias,
                                  const Eigen::Vector3d& accel_bias) const;
  Eigen::Vector3d CorrectedDeltaP(const Eigen::Vector3d& gyro_bias,
                                  const Eigen::Vector3d& accel_bias) const;
};

class ImuPreintegrationFactor final : public ceres::SizedCostFunction<EgoState::kTangentSize,
                                                                      EgoState::kAmbientSize,
                                                                      EgoState::kAmbientSize> {
 public:
  using TangentJacobianMatrix = PreintegratedImu::Matrix18;
  using ResidualVector = Eigen::Matrix<double, EgoState::kTangentSize, 1>;

  /// InvalidArgument when dt_s <= 0, a member is not finite, or the
  /// covariance (symmetrized) is not positive definite (e.g. zero noise
  /// variances, or a single IMU interval: then dp and dv are collinear).
  static Status Create(const PreintegratedImu& preintegrated,
                       std::unique_ptr<ImuPreintegrationFactor>* factor);

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// The unwhitened error e (ErrorStateLayout order).
  ResidualVector Error(const EgoState& ego_k, const EgoState& ego_k1) const;
  /// The whitened residual r = U^-1 e.
  ResidualVector Residual(const EgoState& ego_k, const EgoState& ego_k1) const;
  /// Whitened tangent Jacobians dr/d dx_k and dr/d dx_k+1 (18x18 each).
  /// Either pointer may be nullptr.
  void TangentJacobian(const EgoState& ego_k,
                       const EgoState& ego_k1,
                       TangentJacobianMatrix* J_k,
                       TangentJacobianMatrix* J_k1) const;

  const PreintegratedImu& preintegrated() const { return preintegrated_; }
  /// Sigma, symmetrized.
  const PreintegratedImu::Matrix18& covariance() const { return preintegrated_.covariance; }
  /// U^-1 (lower triangular), with Sigma = U U^T.
  const PreintegratedImu::Matrix18& sqrt_information() const { return sqrt_information_; }

 private:
  ImuPreintegrationFactor(const PreintegratedImu& preintegrated,
                          const PreintegratedImu::Matrix18& sqrt_information)
      : preintegrated_(preintegrated), sqrt_information_(sqrt_information) {}

  // e and, when requested, the unwhitened tangent Jacobians.
  ResidualVector Compute(const EgoState& ego_k,
                         const EgoState& ego_k1,
                         TangentJacobianMatrix* E_k,
                         TangentJacobianMatrix* E_k1) const;

  PreintegratedImu preintegrated_;
  PreintegratedImu::Matrix18 sqrt_information_;
};

}  // namespace swarmlio
