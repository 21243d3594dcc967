#include "swarmlio/testing/jacobian_check.h"

#include <ceres/gradient_checker.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace swarmlio::testing {
namespace {

// ceres::GradientChecker's per-entry rule: relative error, or the absolute
// error when either value is exactly zero.
bool CeresClose(double a, double b, double tolerance) {
  const double abs_error = std::abs(a - b);
  if (a == 0.0 || b == 0.0) return abs_error < tolerance;
  return abs_error / std::max(std::abs(a), std::abs(b)) < tolerance;
}

}  // namespace

::testing::AssertionResult CostFunctionJacobiansAreCorrect(
    const ceres::CostFunction& cost,
    const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters,
    double relative_tolerance) {
  const size_t num_blocks = cost.parameter_block_sizes().size();
  if (manifolds.size() != num_blocks || parameters.size() != num_blocks) {
    return ::testing::AssertionFailure()
           << "expected one manifold and one parameter pointer per parameter block (" << num_blocks
           << ")";
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
  if (!results.return_value || results.local_jacobians.size() != num_blocks ||
      results.local_numeric_jacobians.size() != num_blocks) {
    return ::testing::AssertionFailure() << "evaluation failed: " << results.error_log;
  }
  // Probe also fails when the residuals with and without Jacobians differ.
  const int m = cost.num_residuals();
  Eigen::VectorXd residuals(m);
  if (!cost.Evaluate(parameters.data(), residuals.data(), nullptr)) {
    return ::testing::AssertionFailure() << "evaluation without Jacobians failed";
  }
  for (int i = 0; i < m; ++i) {
    if (!CeresClose(residuals[i], results.residuals[i], relative_tolerance)) {
      return ::testing::AssertionFailure()
             << "residual " << i << " differs with (" << results.residuals[i] << ") and without ("
             << residuals[i] << ") Jacobians";
    }
  }
  // Re-judge the entries Ceres rejected against the scale of their residual
  // row: an entry that is zero in exact arithmetic (e.g. a zero of a skew
  // matrix, lifted through the quaternion Jacobians) has a round-off value on
  // the analytic side and numeric-differentiation noise on the other, and a
  // relative comparison of two noises is meaningless.
  Eigen::VectorXd row_scale = Eigen::VectorXd::Zero(m);
  for (size_t k = 0; k < num_blocks; ++k) {
    const Eigen::MatrixXd& N = results.local_numeric_jacobians[k];
    for (int i = 0; i < m && N.cols() > 0; ++i) {
      row_scale[i] = std::max(row_scale[i], N.row(i).cwiseAbs().maxCoeff());
    }
  }
  std::ostringstream bad;
  int num_bad = 0;
  for (size_t k = 0; k < num_blocks; ++k) {
    const Eigen::MatrixXd& A = results.local_jacobians[k];
    const Eigen::MatrixXd& N = results.local_numeric_jacobians[k];
    for (int i = 0; i < A.rows(); ++i) {
      for (int j = 0; j < A.cols(); ++j) {
        const double a = A(i, j);
        const double n = N(i, j);
        if (CeresClose(a, n, relative_tolerance)) continue;
        const double scale = std::max({std::abs(a), std::abs(n), row_scale[i]});
        if (std::abs(a - n) <= relative_tolerance * scale) continue;
        ++num_bad;
        bad << "  block " << k << " row " << i << " col " << j << ": analytic " << a << ", numeric "
            << n << ", |difference| " << std::abs(a - n) << " > " << relative_tolerance << " * "
            << scale << "\n";
      }
    }
  }
  if (num_bad == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << num_bad << " bad tangent Jacobian entries:\n"
         << bad.str() << "Ceres GradientChecker report:" << results.error_log;
}

FlippedJacobianColumns::FlippedJacobianColumns(const ceres::CostFunction* inner,
                                               int block,
                                               int num_columns,
                                               int first_column)
    : inner_(inner), block_(block), num_columns_(num_columns), first_column_(first_column) {
  set_num_residuals(inner->num_residuals());
  *mutable_parameter_block_sizes() = inner->parameter_block_sizes();
}

bool FlippedJacobianColumns::Evaluate(double const* const* parameters,
                                      double* residuals,
                                      double** jacobians) const {
  if (!inner_->Evaluate(parameters, residuals, jacobians)) return false;
  if (jacobians != nullptr && jacobians[block_] != nullptr) {
    const int cols = parameter_block_sizes()[block_];
    for (int r = 0; r < num_residuals(); ++r) {
      for (int col = first_column_; col < first_column_ + num_columns_; ++col) {
        jacobians[block_][r * cols + col] *= -1.0;
      }
    }
  }
  return true;
}

Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                int n,
                                double step) {
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
