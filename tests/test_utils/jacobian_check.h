// Test helpers that check analytic Jacobians against numeric differentiation
// in the tangent space. Both return a gtest AssertionResult, so a mismatch
// FAILS the test (EXPECT_TRUE(...)) with a readable report; they never just
// print.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace swarmlio::testing {

/// Checks every Jacobian of `cost` at `parameters` with ceres::GradientChecker
/// in the tangent space of each block's manifold (nullptr = Euclidean).
/// `relative_tolerance` is the GradientChecker precision (max relative error
/// per entry); central differences give ~1e-9 on smooth functions.
::testing::AssertionResult CostFunctionJacobiansAreCorrect(
    const ceres::CostFunction& cost,
    const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters,
    double relative_tolerance = 1e-7);

/// Delegates to a cost function and flips the sign of the first
/// `num_columns` ambient columns of parameter block `block` in its Jacobian
/// (e.g. the 4 quaternion columns of the rotation): a Jacobian check must
/// reject the result. Used to prove that a check fails on a flipped sign.
class FlippedJacobianColumns final : public ceres::CostFunction {
 public:
  FlippedJacobianColumns(const ceres::CostFunction* inner, int block, int num_columns);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const ceres::CostFunction* inner_;
  int block_;
  int num_columns_;
};

/// Central-difference Jacobian of f: R^n -> R^m at dx = 0, where f is already
/// written in tangent coordinates (e.g. f(dx) = g(x (+) dx) (-) g(x)).
Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                int n, double step = 1e-6);

/// Compares an analytic Jacobian with a numeric one: every entry must agree
/// within abs_tolerance + rel_tolerance * max(1, |numeric|_max).
::testing::AssertionResult MatricesNear(const Eigen::MatrixXd& analytic,
                                        const Eigen::MatrixXd& numeric,
                                        double abs_tolerance,
                                        double rel_tolerance = 0.0);

}  // namespace swarmlio::testing
