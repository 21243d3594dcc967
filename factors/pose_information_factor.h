// PoseInformationFactor: a Gaussian on the ego pose (rotation, position) in
// the tangent space at a linearization point x_i, given in information form
// (A, b). It carries many residuals' worth of Gauss-Newton information in six
// rows: the point-to-plane rows z_n + h_n^T d of a scan, linearized at x_i,
// have the normal equations A = sum h h^T, b = sum z h (6x6, 6x1), and
//
//   sum_n (z_n + h_n^T d)^2 = |L^T d + L^-1 b|^2 + (sum z_n^2 - b^T A^-1 b)
//
// for A = L L^T. Written with A's eigen-decomposition A = V diag(l) V^T
// (A may be singular: a degenerate scan), rows k with l_k > 1e-12 max(l):
//
//   r_k = sqrt(l_k) v_k^T d + v_k^T b / sqrt(l_k),   other rows 0,
//   d = [Log(R_i^T R_G_b); p_b_in_G - p_i]            (right perturbation)
//
// so |r|^2 equals the sum of squared rows up to a constant, and one
// Gauss-Newton step from x_i is exactly the step with all N rows.
// Tangent Jacobian: dr/d dtheta = S V^T_rot-part Jr^-1(d_rot) (identity at
// x_i), dr/d dp = S V^T_pos-part, with S = diag(sqrt(l_k)); zero for v, b_g,
// b_a, g. Lifted to the quaternion with SO3Manifold::LiftTangentJacobian.
// Used by EsikfUpdate's point-to-plane model (docs/esikf.md, "Compressed
// point rows"); checked with the GradientChecker in
// tests/factors/pose_information_factor_test.cc.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

class PoseInformationFactor final : public ceres::SizedCostFunction<6, EgoState::kAmbientSize> {
 public:
  PoseInformationFactor() = default;
  /// Information A (6x6 symmetric PSD over [dtheta; dp]) and vector b at the
  /// linearization pose (R_G_b, p_b_in_G).
  void Set(const Eigen::Matrix<double, 6, 6>& A, const Eigen::Matrix<double, 6, 1>& b,
           const Eigen::Quaterniond& q_G_b, const Eigen::Vector3d& p_b_in_G);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The residual at `ego`.
  Eigen::Matrix<double, 6, 1> Residual(const EgoState& ego) const;

 private:
  Eigen::Matrix<double, 6, 6> W_ = Eigen::Matrix<double, 6, 6>::Zero();  // S V^T
  Eigen::Matrix<double, 6, 1> c_ = Eigen::Matrix<double, 6, 1>::Zero();  // S^-1 V^T b
  Eigen::Quaterniond q_lin_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_lin_ = Eigen::Vector3d::Zero();
};

}  // namespace swarmlio
