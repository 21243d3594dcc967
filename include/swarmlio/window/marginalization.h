// Marginalizer: removes blocks from the fixed-lag window (issue #12) and keeps
// their information as a linear prior on the blocks they were connected to
// (docs/window.md, "Marginalization prior").
//
// Given the residual blocks that touch the blocks to marginalize (cost
// function, parameter blocks, their manifolds, optional loss), Marginalize()
// evaluates each residual block ONCE at the blocks' current values (the
// linearization point), forms the tangent-space Gauss-Newton system
//
//   J_t = J_ambient PlusJacobian(x)          (per block, ceres::Manifold)
//   H = sum J_t^T J_t,   b = sum J_t^T r      (H dx = -b)
//
// ordered [kept blocks | marginalized blocks], and takes the Schur
// complement onto the kept blocks:
//
//   H* = H_kk - H_km H_mm^+ H_mk,   b* = b_k - H_km H_mm^+ b_m.
//
// H_mm^+ comes from the eigen-decomposition H_mm = V diag(l) V^T with the
// eigenvalues l_k <= min_relative_eigenvalue * max(l) treated as 0 (a
// pseudo-inverse). For the positive semi-definite H of a least-squares
// problem this is exact: a direction v with H_mm v = 0 has H_km v = 0, so an
// unconstrained direction of the marginalized blocks carries no information
// to the kept ones. The result is a MarginalizationPrior (H*, b*, the kept
// blocks' values x0, sizes, manifolds) for MarginalizationPriorFactor
// (factors/marginalization_prior_factor.h), which also explains the
// first-estimate Jacobians.
//
// Robust losses are applied as Ceres applies them (Triggs' correction,
// ceres internal/ceres/corrector.cc): with s = |r|^2 and rho = (rho(s),
// rho'(s), rho''(s)), r and J are scaled by sqrt(rho') when rho'' <= 0 or s = 0,
// else J <- sqrt(rho') (J - alpha/s r r^T J) and r <- sqrt(rho')/(1 - alpha) r
// with alpha = 1 - sqrt(1 + 2 s rho''/rho'). A residual with rho' <= 0 (beyond
// a redescending loss's cut-off) carries no information.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <memory>
#include <string>
#include <vector>

#include "factors/marginalization_prior_factor.h"
#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"

namespace swarmlio::window {

struct MarginalizationOptions {
  /// Eigenvalues of H_mm at or below this fraction of its largest eigenvalue
  /// are treated as 0 (H_mm^+ is a pseudo-inverse) [-]. Eigen-decomposition
  /// round-off is about 1e-16 of the largest eigenvalue.
  double min_relative_eigenvalue = 1e-12;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("min_relative_eigenvalue", min_relative_eigenvalue,
      FieldSpec::InRange(0.0, 1e-3, "",
                         "eigenvalues of H_mm below this fraction of the largest count as 0"));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// One residual block that touches at least one marginalized block, as it
/// would be added to a ceres::Problem.
struct MarginalizationResidualBlock {
  const ceres::CostFunction* cost_function = nullptr;  // not owned
  const ceres::LossFunction* loss_function = nullptr;  // optional, not owned
  std::vector<double*> parameter_blocks;
  /// One per parameter block; nullptr = Euclidean. A block must have the same
  /// manifold in every residual block. Not owned.
  std::vector<const ceres::Manifold*> manifolds;
};

class Marginalizer {
 public:
  /// InvalidArgument when `options` do not validate.
  static Status Create(const MarginalizationOptions& options,
                       std::unique_ptr<Marginalizer>* marginalizer);

  /// Records a residual block (evaluated later, by Marginalize). Its cost
  /// function, loss, manifolds and parameter blocks must stay alive until
  /// then. InvalidArgument when the cost function is null or has no
  /// residuals, a parameter block is null or repeated, or the number of
  /// blocks or manifolds, or a manifold's ambient size, differs from the cost
  /// function's parameter blocks.
  Status AddResidualBlock(const MarginalizationResidualBlock& block);

  /// Evaluates every recorded residual block once at the current values,
  /// eliminates `marginalized` and writes the prior on `kept` (in that order)
  /// to *prior (untouched on error). InvalidArgument when a list is empty,
  /// holds a null or repeated block, the lists overlap, a block of a residual
  /// is in neither list, a listed block is in no residual, a residual touches
  /// no marginalized block (its information would be counted twice), or a
  /// block has different manifolds or sizes in different residuals.
  /// FailedPrecondition when a cost function, manifold or loss fails to
  /// evaluate or returns non-finite values.
  Status Marginalize(const std::vector<double*>& marginalized,
                     const std::vector<double*>& kept,
                     MarginalizationPrior* prior) const;

  int num_residual_blocks() const { return static_cast<int>(residual_blocks_.size()); }
  /// Forgets the recorded residual blocks.
  void Clear() { residual_blocks_.clear(); }

 private:
  explicit Marginalizer(const MarginalizationOptions& options) : options_(options) {}

  MarginalizationOptions options_;
  std::vector<MarginalizationResidualBlock> residual_blocks_;
};

}  // namespace swarmlio::window
