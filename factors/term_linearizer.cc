#include "factors/term_linearizer.h"

#include <string>

namespace swarmlio {

Status LinearizeTerm(const ceres::CostFunction& cost,
                     const double* const* parameters,
                     const std::vector<const ceres::Manifold*>& manifolds,
                     Eigen::VectorXd* residual,
                     std::vector<Eigen::MatrixXd>* tangent_jacobians) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const int m = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  const size_t num_blocks = sizes.size();
  if (manifolds.size() != num_blocks) {
    return Status::InvalidArgument("LinearizeTerm: " + std::to_string(manifolds.size()) +
                                   " manifolds for " + std::to_string(num_blocks) + " blocks");
  }
  std::vector<RowMajor> ambient(num_blocks);
  std::vector<double*> jacobian_pointers(num_blocks);
  for (size_t i = 0; i < num_blocks; ++i) {
    ambient[i].resize(m, sizes[i]);
    jacobian_pointers[i] = ambient[i].data();
  }
  residual->resize(m);
  if (!cost.Evaluate(parameters, residual->data(), jacobian_pointers.data())) {
    return Status::FailedPrecondition("the cost function failed to evaluate");
  }
  if (!residual->allFinite()) return Status::FailedPrecondition("the residual is not finite");
  tangent_jacobians->resize(num_blocks);
  for (size_t i = 0; i < num_blocks; ++i) {
    if (!ambient[i].allFinite()) {
      return Status::FailedPrecondition("the Jacobian of block " + std::to_string(i) +
                                        " is not finite");
    }
    const ceres::Manifold* manifold = manifolds[i];
    if (manifold == nullptr) {
      (*tangent_jacobians)[i] = ambient[i];
      continue;
    }
    RowMajor plus_jacobian(sizes[i], manifold->TangentSize());
    if (!manifold->PlusJacobian(parameters[i], plus_jacobian.data()) ||
        !plus_jacobian.allFinite()) {
      return Status::FailedPrecondition("the PlusJacobian of block " + std::to_string(i) +
                                        " failed");
    }
    (*tangent_jacobians)[i] = ambient[i] * plus_jacobian;
  }
  return Status::Ok();
}

}  // namespace swarmlio
