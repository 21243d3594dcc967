// MarginalizationPriorFactor: the linear prior that the fixed-lag window
// keeps on its remaining blocks when a state leaves the window (issue #12,
// docs/window.md "Marginalization prior"). swarmlio::window::Marginalizer
// (include/swarmlio/window/marginalization.h) builds the MarginalizationPrior
// below; this factor turns it into one Ceres residual over the kept blocks.
//
// Linearization point. The residuals touching the marginalized blocks were
// evaluated once, at the values the blocks had then: x0_i for the kept blocks
// (stored here as ambient copies). In the tangent coordinates of the kept
// blocks at x0, on each block's own ceres::Manifold,
//   dx_i = Minus_i(x_i, x0_i)        (ego: [Log(R0^T R); a - a0], right perturbation)
// (for a block with a quaternion, x_i's quaternion is taken in x0_i's
// hemisphere first: q and -q are the same rotation, but SO3Manifold::Minus is
// the log on S^3 and would see a turn of nearly 2 pi).
// their Gauss-Newton system, after the Schur complement removed the
// marginalized blocks m, is the quadratic model
//   1/2 dx^T H* dx + b*^T dx + const,
//   H* = H_kk - H_km H_mm^+ H_mk,   b* = b_k - H_km H_mm^+ b_m.
//
// Residual (dimension n = the sum of the kept blocks' tangent sizes):
//   H* = V diag(l) V^T;  for the rows k with l_k > eps max(l) (all other rows are 0):
//   J* = diag(sqrt(l_k)) V^T,      r0 = diag(1 / sqrt(l_k)) V^T b*
//   r(x) = J* dx(x) + r0
// so J*^T J* = H*, J*^T r0 = b* (its part in the range of H*, all of it for a
// consistent system) and
//   1/2 |r|^2 = 1/2 dx^T H* dx + b*^T dx + 1/2 b*^T H*^+ b*:
// the quadratic model up to a constant; at x = x0 the cost is
// 1/2 |r0|^2 = 1/2 b*^T H*^+ b*. One Gauss-Newton step from x0 with this factor
// in place of the marginalized residuals and blocks gives exactly the kept
// blocks' step of the full problem (tests/window/marginalization_test.cc).
//
// First-estimate Jacobians (FEJ). J* and r0 are computed once, at x0, and are
// never re-linearized: when the kept blocks move, only dx changes. The
// marginalized residuals cannot be re-linearized anyway (their other blocks
// are gone); fixing J* also keeps the prior consistent: its null space (the
// directions the marginalized information did not constrain, e.g. the global
// position and yaw of a LIO, which no relative residual observes) stays the
// null space at x0. Re-evaluating J* at the moving estimate while the
// information itself was gathered at x0 would give these unobservable
// directions spurious information, and the window would become overconfident
// (Huang, Mourikis, Roumeliotis, "Observability-based rules for designing
// consistent EKF SLAM estimators", IJRR 2010; Dong-Si, Mourikis, "Motion
// tracking with fixed-lag smoothing: algorithm and consistency analysis",
// ICRA 2011).
//
// Jacobian. With x_i (+) delta = Plus_i(x_i, delta), the exact tangent Jacobian is
//   dr/d delta_i = J*_i C_i(x_i),  C_i = d Minus_i(x_i (+) delta, x0_i)/d delta at 0,
//   C_i = blockdiag(Jr^-1(dx_rot), I) for a block whose tangent starts with a
//   rotation (SO3Manifold's right perturbation; Minus is the log on S^3), I else,
// and C_i = I at x = x0. C_i is the derivative of the chart dx(x), not a
// re-linearization: the residual stays the fixed linear model in dx. The
// ambient Jacobian handed to Ceres is J*_i C_i MinusJacobian_i(x_i)
// (ceres::Manifold::MinusJacobian, exactly J* MinusJacobian at x0); Ceres
// multiplies it by PlusJacobian_i(x_i) and gets J*_i C_i back, because
// MinusJacobian PlusJacobian = I.
//
// Supported manifolds (C_i is known in closed form): nullptr (Euclidean),
// ceres::EuclideanManifold<ceres::DYNAMIC>, SO3Manifold, EgoStateManifold,
// GlobalExtrinsicManifold. Create() rejects any other manifold rather than
// hand Ceres an approximate Jacobian.
//
// Known limitation: the prior is the marginalized residuals' linear model at
// x0. The kept blocks' other factors are re-linearized at the current
// estimate, which drifts from x0 as the window runs; the prior ignores the
// marginalized residuals' curvature (second order in |x - x0|) and, unless
// the other factors also keep first estimates, the kept states are linearized
// at two different points in the same problem. The window keeps this small
// by marginalizing only states that have converged.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"

namespace swarmlio {

/// The Schur complement of a marginalization, over the kept blocks in order
/// (built by swarmlio::window::Marginalizer).
struct MarginalizationPrior {
  /// H* (n x n, symmetric positive semi-definite) in the kept blocks' tangent
  /// coordinates at x0, blocks in the order below.
  Eigen::MatrixXd information;
  /// b* (n): the gradient of the quadratic model at x0 (J^T r, not -J^T r).
  Eigen::VectorXd gradient;
  /// The kept parameter blocks (the caller's storage); the prior factor's
  /// parameter blocks, in this order.
  std::vector<double*> parameter_blocks;
  /// x0_i: copies of the kept blocks' ambient values at the linearization.
  std::vector<Eigen::VectorXd> linearization_points;
  /// One per kept block; nullptr = Euclidean. Not owned: each manifold must
  /// outlive every factor built from this prior.
  std::vector<const ceres::Manifold*> manifolds;
  std::vector<int> ambient_sizes;
  std::vector<int> tangent_sizes;
  /// Diagnostics: the marginalized blocks' tangent dimension, and the rank of
  /// H_mm that was inverted (smaller when the marginalized residuals left a
  /// direction of the marginalized blocks unconstrained).
  int marginalized_dim = 0;
  int marginalized_rank = 0;

  /// n = the sum of tangent_sizes.
  int TangentDim() const;
};

struct MarginalizationPriorFactorOptions {
  /// Eigenvalues of H* at or below this fraction of the largest one are
  /// dropped (their rows of J* and r0 are 0) [-].
  double min_relative_eigenvalue = 1e-12;
  /// Create() rejects H* with an eigenvalue below -this * the largest one
  /// (not positive semi-definite beyond round-off) [-].
  double max_relative_negative_eigenvalue = 1e-9;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("min_relative_eigenvalue", min_relative_eigenvalue,
      FieldSpec::InRange(0.0, 1e-3, "",
                         "eigenvalues of H* below this fraction of the largest are dropped"));
    v("max_relative_negative_eigenvalue", max_relative_negative_eigenvalue,
      FieldSpec::InRange(0.0, 1e-3, "", "largest tolerated negative eigenvalue of H*, relative"));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

class MarginalizationPriorFactor final : public ceres::CostFunction {
 public:
  /// InvalidArgument when `options` do not validate, the prior's sizes are
  /// inconsistent (per-block vectors of different lengths, a manifold whose
  /// sizes differ from the block's, H*/b* not n x n / n), a value is not
  /// finite, a manifold is not supported (see the header comment), or H* has
  /// an eigenvalue below -max_relative_negative_eigenvalue * max.
  static Status Create(const MarginalizationPrior& prior,
                       const MarginalizationPriorFactorOptions& options,
                       std::unique_ptr<MarginalizationPriorFactor>* factor);

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// dx = [Minus_i(x_i, x0_i)]_i (n); false when a manifold's Minus fails.
  bool Delta(double const* const* parameters, Eigen::VectorXd* dx) const;

  /// J* (n x n, FEJ: fixed at x0) and r0 = r(x0) (n).
  const Eigen::MatrixXd& sqrt_information() const { return sqrt_information_; }
  const Eigen::VectorXd& linearization_residual() const { return linearization_residual_; }
  /// The number of nonzero rows of J* (eigenvalues of H* that were kept).
  int rank() const { return rank_; }

 private:
  // How C_i = d Minus(x (+) delta, x0)/d delta depends on x for one block.
  enum class Chart { kEuclidean, kLeadingRotation };

  MarginalizationPriorFactor() = default;

  std::vector<Eigen::VectorXd> linearization_points_;
  std::vector<const ceres::Manifold*> manifolds_;
  std::vector<Chart> charts_;
  std::vector<int> tangent_sizes_;
  std::vector<int> tangent_offsets_;
  Eigen::MatrixXd sqrt_information_;        // J*
  Eigen::VectorXd linearization_residual_;  // r0
  int rank_ = 0;
};

}  // namespace swarmlio
