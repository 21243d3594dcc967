// PriorFactor: the IEKF prior of the predicted state as one Ceres residual
// over the ego block and every teammate block of a SwarmState, in layout order
// (docs/esikf.md, docs/state.md).
//
// Parameter blocks (ambient): ego (19) = [q_G_b (x y z w) | p | v | b_g | b_a | g],
// then one (7) = [q_Gi_Gj (x y z w) | p_Gj_in_Gi] per teammate in slot order.
//
// Residual (dimension n = layout.Dim()):
//   e = x (-) x_hat                        (paper boxminus, shortest rotation)
//   r = L^T e,       L L^T = P_hat^-1
// so that |r|^2 = e^T P_hat^-1 e. With the lower Cholesky factor P_hat = U U^T
// we use L^T = U^-1 (a triangular solve, no explicit inverse).
//
// Tangent Jacobian (right perturbation x (+) dx, docs/conventions.md):
//   e(dx) = [Log(R_hat^T R Exp(dr)); a + da - a_hat] per block, and
//   Log(Exp(w) Exp(dr)) = w + Jr^-1(w) dr + O(|dr|^2), hence
//   de/d dx = J = blockdiag(Jr^-1(e_R_ego), I_15, Jr^-1(e_R_1), I_3, ...)
//   dr/d dx = U^-1 J.
// At x == x_hat, J = I. Away from x_hat this is the J^-1 correction of the
// prior term in FAST-LIO2's iterated update (P_J = J^-1 P J^-T). Each
// rotation column triple is lifted to the quaternion's ambient coordinates
// with SO3Manifold::LiftTangentJacobian; Euclidean columns are copied.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

class PriorFactor final : public ceres::CostFunction {
 public:
  /// `covariance_cholesky` is the lower Cholesky factor U of P_hat (P_hat =
  /// U U^T), of size x_hat.Dim(); see CholeskyOfCovariance.
  PriorFactor(SwarmState x_hat, Eigen::MatrixXd covariance_cholesky);

  /// Lower Cholesky factor of a symmetric positive-definite covariance.
  /// Returns false (and leaves *cholesky untouched) when P is not square or
  /// not positive definite.
  static bool CholeskyOfCovariance(const Eigen::MatrixXd& P, Eigen::MatrixXd* cholesky);

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// The state the parameter blocks encode (layout of x_hat).
  SwarmState StateFromParameters(double const* const* parameters) const;
  /// r = U^-1 (x (-) x_hat).
  Eigen::VectorXd Residual(const SwarmState& x) const;
  /// dr/d dx (n x n) in the tangent space of x.
  Eigen::MatrixXd TangentJacobian(const SwarmState& x) const;
  /// J = d(x (-) x_hat)/d dx = blockdiag(Jr^-1(...), I, ...) (n x n).
  Eigen::MatrixXd BoxMinusJacobian(const SwarmState& x) const;

  const SwarmState& x_hat() const { return x_hat_; }

 private:
  SwarmState x_hat_;
  Eigen::MatrixXd covariance_cholesky_;  // U, lower triangular
};

}  // namespace swarmlio
