#include "factors/prior_factor.h"

#include <Eigen/Cholesky>
#include <utility>

#include "factors/so3_manifold.h"
#include "swarmlio/common/check.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Copies the tangent columns [col, col + size) of J_t (one parameter block
// whose first three tangent coordinates are a rotation) into the ambient
// (n x (size + 1)) row-major Jacobian, lifting the rotation columns.
void WriteBlockJacobian(
    const Eigen::MatrixXd& J_t, int col, int size, const double* x, double* jacobian) {
  const int n = static_cast<int>(J_t.rows());
  Eigen::Map<RowMajorMatrix> J(jacobian, n, size + 1);
  const Eigen::Matrix<double, 3, 4> minus_jacobian = SO3Manifold::MinusJacobianAt(x);
  J.leftCols<4>() = J_t.middleCols<3>(col) * minus_jacobian;
  J.rightCols(size - 3) = J_t.middleCols(col + 3, size - 3);
}

}  // namespace

PriorFactor::PriorFactor(SwarmState x_hat, Eigen::MatrixXd covariance_cholesky)
    : x_hat_(std::move(x_hat)), covariance_cholesky_(std::move(covariance_cholesky)) {
  const int n = x_hat_.Dim();
  CHECK_EQ(covariance_cholesky_.rows(), n);
  CHECK_EQ(covariance_cholesky_.cols(), n);
  set_num_residuals(n);
  std::vector<int32_t>* sizes = mutable_parameter_block_sizes();
  sizes->push_back(EgoState::kAmbientSize);
  for (int i = 0; i < x_hat_.layout().NumTeammates(); ++i) {
    sizes->push_back(GlobalExtrinsic::kAmbientSize);
  }
}

bool PriorFactor::CholeskyOfCovariance(const Eigen::MatrixXd& P, Eigen::MatrixXd* cholesky) {
  if (P.rows() != P.cols() || P.rows() == 0 || !P.allFinite()) return false;
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (P + P.transpose()));
  if (llt.info() != Eigen::Success) return false;
  Eigen::MatrixXd U = llt.matrixL();
  if ((U.diagonal().array() <= 0.0).any()) return false;
  *cholesky = std::move(U);
  return true;
}

SwarmState PriorFactor::StateFromParameters(double const* const* parameters) const {
  SwarmState x = x_hat_;
  x.ego = EgoState::FromParameters(parameters[0]);
  const std::vector<int>& ids = x_hat_.layout().teammate_ids();
  for (size_t s = 0; s < ids.size(); ++s) {
    x.teammate(ids[s]) = GlobalExtrinsic::FromParameters(parameters[1 + s]);
  }
  return x;
}

Eigen::VectorXd PriorFactor::Residual(const SwarmState& x) const {
  return covariance_cholesky_.triangularView<Eigen::Lower>().solve(x.BoxMinus(x_hat_));
}

Eigen::MatrixXd PriorFactor::BoxMinusJacobian(const SwarmState& x) const {
  const Eigen::VectorXd e = x.BoxMinus(x_hat_);
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(e.size(), e.size());
  const Segment rot = ErrorStateLayout::kRotation;
  J.block<3, 3>(rot.offset, rot.offset) = so3::RightJacobianInverse(e.segment<3>(rot.offset));
  for (int id : x.layout().teammate_ids()) {
    const int o = x.layout().TeammateRotation(id).offset;
    J.block<3, 3>(o, o) = so3::RightJacobianInverse(e.segment<3>(o));
  }
  return J;
}

Eigen::MatrixXd PriorFactor::TangentJacobian(const SwarmState& x) const {
  return covariance_cholesky_.triangularView<Eigen::Lower>().solve(BoxMinusJacobian(x));
}

bool PriorFactor::Evaluate(double const* const* parameters,
                           double* residuals,
                           double** jacobians) const {
  const SwarmState x = StateFromParameters(parameters);
  const int n = x_hat_.Dim();
  Eigen::Map<Eigen::VectorXd>(residuals, n) = Residual(x);
  if (jacobians == nullptr) return true;
  const int num_blocks = 1 + x_hat_.layout().NumTeammates();
  bool any = false;
  for (int b = 0; b < num_blocks; ++b) any = any || jacobians[b] != nullptr;
  if (!any) return true;

  const Eigen::MatrixXd J_t = TangentJacobian(x);
  if (jacobians[0] != nullptr) {
    WriteBlockJacobian(J_t, 0, ErrorStateLayout::kEgoDim, parameters[0], jacobians[0]);
  }
  const std::vector<int>& ids = x_hat_.layout().teammate_ids();
  for (size_t s = 0; s < ids.size(); ++s) {
    if (jacobians[1 + s] == nullptr) continue;
    WriteBlockJacobian(J_t, x_hat_.layout().TeammateBlock(ids[s]).offset,
                       ErrorStateLayout::kTeammateDim, parameters[1 + s], jacobians[1 + s]);
  }
  return true;
}

}  // namespace swarmlio
