// SO3Manifold: the rotation part of every state block, with the paper's right
// perturbation (Sec. III-D), stored as a unit quaternion in Eigen's
// coefficient order (x, y, z, w).
//
//   Plus(q, dr)    = q (x) Exp(dr)                 Exp(dr) = [cos(|dr|/2), sin(|dr|/2) dr/|dr|]
//   Minus(q1, q2)  = LogS3(q2^* (x) q1)             the inverse of Plus on S^3
//   PlusJacobian   = d Plus(q, dr)/d dr |dr=0  = 1/2 [ w I + [v]x ; -v^T ]      (4x3)
//   MinusJacobian  = d Minus(y, q)/d y  |y=q   = 2  [ w I - [v]x ,  -v   ]      (3x4)
// with q = (v, w). MinusJacobian * PlusJacobian = I, and MinusJacobian =
// 4 PlusJacobian^T, so an analytic cost function can compute its Jacobian J_t
// in the tangent space and hand Ceres the ambient Jacobian J_t * MinusJacobian
// (see LiftTangentJacobian below): Ceres multiplies it by PlusJacobian and gets
// J_t back exactly.
//
// Note on the double cover: Minus is the logarithm on S^3 (angles up to 2 pi)
// so that Plus(x, Minus(y, x)) == y holds coefficient-wise, as Ceres's
// manifold invariants require. For quaternions in the same hemisphere
// (w of q2^* q1 >= 0; Plus keeps this for |dr| < pi) it equals the paper's
// boxminus Log(R2^T R1). SwarmState::BoxMinus always takes the shortest rotation.
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>

namespace swarmlio {

class SO3Manifold final : public ceres::Manifold {
 public:
  static constexpr int kAmbientSize = 4;
  static constexpr int kTangentSize = 3;

  int AmbientSize() const override { return kAmbientSize; }
  int TangentSize() const override { return kTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  /// The 3x4 MinusJacobian at quaternion x (x, y, z, w), as a fixed matrix.
  static Eigen::Matrix<double, 3, 4> MinusJacobianAt(const double* x);

  /// Ambient (k x 4) Jacobian whose product with PlusJacobian(x) is the given
  /// tangent Jacobian (k x 3): J_tangent * MinusJacobian(x).
  template <int Rows>
  static Eigen::Matrix<double, Rows, 4> LiftTangentJacobian(
      const Eigen::Matrix<double, Rows, 3>& J_tangent, const double* x) {
    return J_tangent * MinusJacobianAt(x);
  }
};

}  // namespace swarmlio
