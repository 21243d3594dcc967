// LinearizeTerm: one residual block (a Ceres cost function on its parameter
// blocks) linearized at the blocks' current values, in the tangent space of
// each block's manifold:
//
//   r   = f(x_1, ..., x_n)
//   J_i = d f(x_1, ..., x_i (+) d_i, ..., x_n) / d d_i  at d_i = 0
//       = (d f / d x_i) * (d (x_i (+) d) / d d)|_{d = 0}
//
// i.e. the ambient Jacobian that CostFunction::Evaluate returns (row-major,
// m x ambient_i) times the manifold's PlusJacobian (ambient_i x tangent_i);
// a block without a manifold (nullptr) is Euclidean and keeps its ambient
// Jacobian. The one place that does this for the filter's posterior
// covariance (src/lio/esikf_update.cc), the window's newest covariance
// (src/window/window_solve.cc) and the marginalization
// (src/window/marginalization.cc).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio {

/// Evaluates `cost` at `parameters` (one pointer per parameter block, as
/// Ceres takes them) into `*residual` (m) and `*tangent_jacobians` (one
/// m x tangent_i matrix per block; `manifolds[i]` nullptr = Euclidean).
/// FailedPrecondition naming what failed when the cost does not evaluate,
/// the residual or an ambient Jacobian is not finite, or a PlusJacobian
/// fails or is not finite.
Status LinearizeTerm(const ceres::CostFunction& cost,
                     const double* const* parameters,
                     const std::vector<const ceres::Manifold*>& manifolds,
                     Eigen::VectorXd* residual,
                     std::vector<Eigen::MatrixXd>* tangent_jacobians);

}  // namespace swarmlio
