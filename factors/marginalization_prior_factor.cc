#include "factors/marginalization_prior_factor.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "factors/so3_manifold.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

std::string BlockName(size_t i) { return "kept block " + std::to_string(i); }

}  // namespace

int MarginalizationPrior::TangentDim() const {
  int n = 0;
  for (int t : tangent_sizes) n += t;
  return n;
}

Status MarginalizationPriorFactor::Create(const MarginalizationPrior& prior,
                                          const MarginalizationPriorFactorOptions& options,
                                          std::unique_ptr<MarginalizationPriorFactor>* factor) {
  const std::string options_error = options.Validate();
  if (!options_error.empty()) return Status::InvalidArgument(options_error);
  const size_t num_blocks = prior.ambient_sizes.size();
  if (num_blocks == 0) return Status::InvalidArgument("the prior has no kept blocks");
  if (prior.tangent_sizes.size() != num_blocks || prior.manifolds.size() != num_blocks ||
      prior.linearization_points.size() != num_blocks) {
    return Status::InvalidArgument(
        "ambient_sizes, tangent_sizes, manifolds and linearization_points differ in length");
  }
  if (!prior.parameter_blocks.empty() && prior.parameter_blocks.size() != num_blocks) {
    return Status::InvalidArgument("parameter_blocks and ambient_sizes differ in length");
  }

  std::unique_ptr<MarginalizationPriorFactor> out(new MarginalizationPriorFactor());
  int n = 0;
  for (size_t i = 0; i < num_blocks; ++i) {
    const int ambient = prior.ambient_sizes[i];
    const int tangent = prior.tangent_sizes[i];
    const ceres::Manifold* manifold = prior.manifolds[i];
    if (ambient <= 0 || tangent <= 0 || tangent > ambient) {
      return Status::InvalidArgument(BlockName(i) + ": invalid ambient/tangent sizes " +
                                     std::to_string(ambient) + "/" + std::to_string(tangent));
    }
    const Eigen::VectorXd& x0 = prior.linearization_points[i];
    if (x0.size() != ambient || !x0.allFinite()) {
      return Status::InvalidArgument(BlockName(i) +
                                     ": linearization point has the wrong size or is not finite");
    }
    Chart chart = Chart::kEuclidean;
    if (manifold == nullptr) {
      if (tangent != ambient) {
        return Status::InvalidArgument(BlockName(i) + ": Euclidean block with tangent != ambient");
      }
    } else {
      if (manifold->AmbientSize() != ambient || manifold->TangentSize() != tangent) {
        return Status::InvalidArgument(BlockName(i) + ": manifold sizes differ from the block's");
      }
      if (dynamic_cast<const SO3Manifold*>(manifold) != nullptr ||
          dynamic_cast<const EgoStateManifold*>(manifold) != nullptr ||
          dynamic_cast<const GlobalExtrinsicManifold*>(manifold) != nullptr) {
        chart = Chart::kLeadingRotation;
      } else if (dynamic_cast<const ceres::EuclideanManifold<ceres::DYNAMIC>*>(manifold) ==
                 nullptr) {
        return Status::InvalidArgument(
            BlockName(i) +
            ": unsupported manifold (supported: nullptr, ceres::EuclideanManifold<DYNAMIC>, "
            "SO3Manifold, EgoStateManifold, GlobalExtrinsicManifold)");
      }
    }
    out->linearization_points_.push_back(x0);
    out->manifolds_.push_back(manifold);
    out->charts_.push_back(chart);
    out->tangent_sizes_.push_back(tangent);
    out->tangent_offsets_.push_back(n);
    n += tangent;
  }
  if (prior.information.rows() != n || prior.information.cols() != n ||
      prior.gradient.size() != n) {
    return Status::InvalidArgument("information must be " + std::to_string(n) + " x " +
                                   std::to_string(n) + " and gradient " + std::to_string(n) +
                                   " (the sum of the tangent sizes)");
  }
  if (!prior.information.allFinite() || !prior.gradient.allFinite()) {
    return Status::InvalidArgument("information or gradient is not finite");
  }

  // H* = V diag(l) V^T; rows k with l_k > eps max(l): sqrt(l_k) v_k^T and v_k^T b* / sqrt(l_k).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(
      0.5 * (prior.information + prior.information.transpose()));
  if (eig.info() != Eigen::Success) {
    return Status::InvalidArgument("eigen-decomposition of the information failed");
  }
  const Eigen::VectorXd& l = eig.eigenvalues();
  const double l_max = std::max(l.maxCoeff(), 0.0);
  if (l.minCoeff() < -options.max_relative_negative_eigenvalue * l_max) {
    return Status::InvalidArgument("information is not positive semi-definite (eigenvalue " +
                                   std::to_string(l.minCoeff()) + ", largest " +
                                   std::to_string(l_max) + ")");
  }
  const double threshold = options.min_relative_eigenvalue * l_max;
  out->sqrt_information_ = Eigen::MatrixXd::Zero(n, n);
  out->linearization_residual_ = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    if (!(l[k] > threshold) || l[k] <= 0.0) continue;
    const double s = std::sqrt(l[k]);
    out->sqrt_information_.row(k) = s * eig.eigenvectors().col(k).transpose();
    out->linearization_residual_[k] = eig.eigenvectors().col(k).dot(prior.gradient) / s;
    ++out->rank_;
  }

  out->set_num_residuals(n);
  *out->mutable_parameter_block_sizes() =
      std::vector<int32_t>(prior.ambient_sizes.begin(), prior.ambient_sizes.end());
  *factor = std::move(out);
  return Status::Ok();
}

bool MarginalizationPriorFactor::Delta(double const* const* parameters, Eigen::VectorXd* dx) const {
  dx->resize(num_residuals());
  for (size_t i = 0; i < manifolds_.size(); ++i) {
    const Eigen::VectorXd& x0 = linearization_points_[i];
    double* out = dx->data() + tangent_offsets_[i];
    const Eigen::Map<const Eigen::VectorXd> x(parameters[i], x0.size());
    if (manifolds_[i] == nullptr) {
      Eigen::Map<Eigen::VectorXd>(out, x0.size()) = x - x0;
      continue;
    }
    if (charts_[i] == Chart::kLeadingRotation && x.head<4>().dot(x0.head<4>()) < 0.0) {
      // q and -q are the same rotation; Minus (the log on S^3) would see a
      // turn of nearly 2 pi. Take the quaternion in x0's hemisphere.
      Eigen::VectorXd same_rotation = x;
      same_rotation.head<4>() = -same_rotation.head<4>();
      if (!manifolds_[i]->Minus(same_rotation.data(), x0.data(), out)) return false;
    } else if (!manifolds_[i]->Minus(parameters[i], x0.data(), out)) {
      return false;
    }
  }
  return true;
}

bool MarginalizationPriorFactor::Evaluate(double const* const* parameters,
                                          double* residuals,
                                          double** jacobians) const {
  Eigen::VectorXd dx;
  if (!Delta(parameters, &dx)) return false;
  const int n = num_residuals();
  Eigen::Map<Eigen::VectorXd>(residuals, n) = sqrt_information_ * dx + linearization_residual_;
  if (jacobians == nullptr) return true;

  for (size_t i = 0; i < manifolds_.size(); ++i) {
    if (jacobians[i] == nullptr) continue;
    const int offset = tangent_offsets_[i];
    const int tangent = tangent_sizes_[i];
    // J*_i C_i, C_i = blockdiag(Jr^-1(dx_rot), I) or I.
    Eigen::MatrixXd J_t = sqrt_information_.middleCols(offset, tangent);
    if (charts_[i] == Chart::kLeadingRotation) {
      J_t.leftCols<3>() = J_t.leftCols<3>() * so3::RightJacobianInverse(dx.segment<3>(offset));
    }
    const int ambient = static_cast<int>(linearization_points_[i].size());
    Eigen::Map<RowMajorMatrix> J(jacobians[i], n, ambient);
    if (manifolds_[i] == nullptr) {
      J = J_t;
      continue;
    }
    RowMajorMatrix minus_jacobian(tangent, ambient);
    if (!manifolds_[i]->MinusJacobian(parameters[i], minus_jacobian.data())) return false;
    J.noalias() = J_t * minus_jacobian;
  }
  return true;
}

}  // namespace swarmlio
