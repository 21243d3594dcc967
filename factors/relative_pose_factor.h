// RelativePoseFactor: a measured relative pose T_a_b between two ego states
// of the same drone, the body at time a and the body at time b (a loop
// closure, a relocalization against an earlier scan, a retrodicted sensor);
// the two states are named with StateKey::EgoAt (docs/architecture.md
// "Named states").
//
// Parameter blocks (ambient): ego a (19) and ego b (19), each
// [q_G_b (x y z w) | p_b_in_G | v | b_g | b_a | g_in_G].
// Constant: the measurement (R_a_b, p_b_in_a) and a 6x6 square-root
// information L over [rotation; translation] (|r|^2 = e^T L^T L e, e.g. L
// the transposed Cholesky factor of the information, or its inverse
// covariance root).
//
//   R_a_b(x) = R_G_a^T R_G_b,   p_b_in_a(x) = R_G_a^T (p_b_in_G - p_a_in_G)
//   e_rot = Log(R_a_b_meas^T R_G_a^T R_G_b)       (rotation error, in b)
//   e_pos = R_G_a^T (p_b_in_G - p_a_in_G) - p_b_in_a_meas   (in a)
//   r = L [e_rot; e_pos]
//
// Tangent Jacobians of e (right perturbation R Exp(dtheta), p + dp, in
// ErrorStateLayout order [dtheta dp dv dbg dba dg]; E = R_a_b_meas^T R_a_b):
//   de_rot/ddtheta_a = -Jr^-1(e_rot) R_G_b^T R_G_a   (E Exp(-R_a_b^T dtheta_a))
//   de_rot/ddtheta_b =  Jr^-1(e_rot)
//   de_pos/ddtheta_a =  [R_G_a^T (p_b_in_G - p_a_in_G)]x   (Exp(-d) u = u - d x u)
//   de_pos/ddp_a     = -R_G_a^T
//   de_pos/ddp_b     =  R_G_a^T
//   zero for de_rot/dp, de_pos/ddtheta_b and every v, b_g, b_a, g column.
// The residual Jacobian is L times these; the rotation columns are lifted to
// the quaternion with SO3Manifold::LiftTangentJacobian. Checked with the
// GradientChecker in tests/factors/relative_pose_factor_test.cc.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

class RelativePoseFactor final
    : public ceres::SizedCostFunction<6, EgoState::kAmbientSize, EgoState::kAmbientSize> {
 public:
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using TangentJacobian6 = Eigen::Matrix<double, 6, EgoState::kTangentSize>;

  /// The measured pose of body b in body a (q_a_b, p_b_in_a [m]) and the
  /// square-root information L (6x6, rows over [rotation [rad]; position
  /// [m]]); L must be finite (CHECK).
  RelativePoseFactor(const Eigen::Quaterniond& q_a_b,
                     const Eigen::Vector3d& p_b_in_a,
                     const Matrix6& sqrt_information);

  /// L from a 6x6 symmetric positive-definite covariance of [rotation;
  /// position] (L = U^-1 with covariance = U U^T, lower Cholesky); CHECKs it.
  static Matrix6 SqrtInformationOfCovariance(const Matrix6& covariance);

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// The unwhitened error [e_rot; e_pos].
  Vector6 Error(const EgoState& ego_a, const EgoState& ego_b) const;
  /// The whitened residual r = L e.
  Vector6 Residual(const EgoState& ego_a, const EgoState& ego_b) const;
  /// Whitened tangent Jacobians dr/d dx_a and dr/d dx_b (6x18 each); either
  /// pointer may be nullptr.
  void TangentJacobian(const EgoState& ego_a,
                       const EgoState& ego_b,
                       TangentJacobian6* J_a,
                       TangentJacobian6* J_b) const;

  const Matrix6& sqrt_information() const { return sqrt_information_; }

 private:
  Eigen::Quaterniond q_a_b_;
  Eigen::Vector3d p_b_in_a_;
  Matrix6 sqrt_information_;
};

}  // namespace swarmlio
