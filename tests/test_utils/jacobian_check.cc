#include "test_utils/jacobian_check.h"

#include <ceres/gradient_checker.h>

#include <sstream>

namespace swarmlio::testing {

::testing::AssertionResult CostFunctionJacobiansAreCorrect(
    const ceres::CostFunction& cost,
    const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters,
    double relative_tolerance) {
  if (manifolds.size() != cost.parameter_block_sizes().size() ||
      parameters.size() != manifolds.size()) {
    return ::testing::AssertionFailure()
           << "expected one manifold and one parameter pointer per parameter block ("
           << cost.parameter_block_sizes().size() << ")";
  }
  // Ceres's GradientChecker differentiates with Ridders' method; its default
  // first step (1e-2 relative) is too coarse near the identity rotation and
  // for large-error prior residuals, so start smaller.
  ceres::NumericDiffOptions options;
  options.relative_step_size = 1e-6;
  options.ridders_relative_initial_step_size = 1e-4;
  ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  if (checker.Probe(parameters.data(), relative_tolerance, &results)) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "Jacobian mismatch (max relative error "
                                       << results.maximum_relative_error << "):\n"
                                       << results.error_log;
}

FlippedJacobianColumns::FlippedJacobianColumns(const ceres::CostFunction* inner, int block,
                                               int num_columns)
    : inner_(inner), block_(block), num_columns_(num_columns) {
  set_num_residuals(inner->num_residuals());
  *mutable_parameter_block_sizes() = inner->parameter_block_sizes();
}

bool FlippedJacobianColumns::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  if (!inner_->Evaluate(parameters, residuals, jacobians)) return false;
  if (jacobians != nullptr && jacobians[block_] != nullptr) {
    const int cols = parameter_block_sizes()[block_];
    for (int r = 0; r < num_residuals(); ++r) {
      for (int col = 0; col < num_columns_; ++col) jacobians[block_][r * cols + col] *= -1.0;
    }
  }
  return true;
}

Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                int n, double step) {
  const Eigen::VectorXd f0 = f(Eigen::VectorXd::Zero(n));
  Eigen::MatrixXd J(f0.size(), n);
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
    d[k] = step;
    const Eigen::VectorXd fp = f(d);
    d[k] = -step;
    const Eigen::VectorXd fm = f(d);
    J.col(k) = (fp - fm) / (2.0 * step);
  }
  return J;
}

::testing::AssertionResult MatricesNear(const Eigen::MatrixXd& analytic,
                                        const Eigen::MatrixXd& numeric,
                                        double abs_tolerance,
                                        double rel_tolerance) {
  if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols()) {
    return ::testing::AssertionFailure()
           << "size mismatch: analytic " << analytic.rows() << "x" << analytic.cols()
           << ", numeric " << numeric.rows() << "x" << numeric.cols();
  }
  const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
  const double tol = abs_tolerance + rel_tolerance * scale;
  const double err = (analytic - numeric).cwiseAbs().maxCoeff();
  if (err <= tol) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os << "max abs difference " << err << " > tolerance " << tol << "\nanalytic:\n"
     << analytic << "\nnumeric:\n"
     << numeric;
  return ::testing::AssertionFailure() << os.str();
}

}  // namespace swarmlio::testing
