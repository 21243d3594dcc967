// Helpers that check analytic Jacobians against numeric differentiation in
// the tangent space, for this project's factors and for your own
// (docs/factors.md). The checks return a gtest AssertionResult, so a mismatch
// FAILS the test (EXPECT_TRUE(...)) with a readable report; they never just
// print. Installed with the library target swarmlio::swarmlio_testing
// (find_package(swarmlio COMPONENTS testing); needs Ceres and GoogleTest).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace swarmlio::testing {

/// Checks every Jacobian of `cost` at `parameters` with ceres::GradientChecker
/// (Ridders' numeric differentiation) in the tangent space of each block's
/// manifold (nullptr = Euclidean). An entry (analytic a, numeric n) of
/// residual row i passes when Ceres's rule passes (|a - n| <
/// relative_tolerance * max(|a|, |n|), or < relative_tolerance when a or n is
/// exactly 0), or when
///   |a - n| <= relative_tolerance * max(|a|, |n|, s_i),
/// s_i = the largest numeric |entry| of row i over all blocks, so entries that
/// are zero in exact arithmetic but carry round-off are judged on the scale of
/// their row. Also fails when the residuals with and without Jacobians
/// differ. Central differences give ~1e-9 on smooth functions.
::testing::AssertionResult CostFunctionJacobiansAreCorrect(
    const ceres::CostFunction& cost,
    const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters,
    double relative_tolerance = 1e-7);

/// Delegates to a cost function and flips the sign of the `num_columns`
/// ambient columns [first_column, first_column + num_columns) of parameter
/// block `block` in its Jacobian (e.g. the 4 quaternion columns of the
/// rotation, or columns 4..6 for the position of an ego block): a Jacobian
/// check must reject the result. Used to prove that a check fails on a
/// flipped sign. `inner` must outlive this object.
class FlippedJacobianColumns final : public ceres::CostFunction {
 public:
  FlippedJacobianColumns(const ceres::CostFunction* inner,
                         int block,
                         int num_columns,
                         int first_column = 0);
  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

 private:
  const ceres::CostFunction* inner_;
  int block_;
  int num_columns_;
  int first_column_;
};

/// Central-difference Jacobian of f: R^n -> R^m at dx = 0, where f is already
/// written in tangent coordinates (e.g. f(dx) = g(x (+) dx) (-) g(x)).
Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                int n,
                                double step = 1e-6);

/// Compares an analytic Jacobian with a numeric one: every entry must agree
/// within abs_tolerance + rel_tolerance * max(1, |numeric|_max).
::testing::AssertionResult MatricesNear(const Eigen::MatrixXd& analytic,
                                        const Eigen::MatrixXd& numeric,
                                        double abs_tolerance,
                                        double rel_tolerance = 0.0);

}  // namespace swarmlio::testing
