#include "swarmlio/window/marginalization.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "factors/term_linearizer.h"

namespace swarmlio::window {
namespace {

// One parameter block of the system, in [kept | marginalized] order.
struct Block {
  double* values = nullptr;
  bool kept = false;
  bool touched = false;
  int ambient = 0;
  int tangent = 0;
  int offset = 0;  // in the tangent system
  const ceres::Manifold* manifold = nullptr;
};

std::string ResidualName(size_t r) { return "residual block " + std::to_string(r); }

// Ceres's robust-loss correction (internal/ceres/corrector.cc): rescales the
// residual and the tangent Jacobians in place so that J^T J and J^T r are the
// Gauss-Newton terms of rho(|r|^2) / 2. False when rho is not finite.
bool ApplyLoss(const ceres::LossFunction& loss,
               Eigen::VectorXd* r,
               std::vector<Eigen::MatrixXd>* jacobians) {
  const double s = r->squaredNorm();
  double rho[3];
  loss.Evaluate(s, rho);
  if (!std::isfinite(rho[0]) || !std::isfinite(rho[1]) || !std::isfinite(rho[2])) return false;
  if (rho[1] <= 0.0) {  // beyond a redescending loss's cut-off: no information
    r->setZero();
    for (Eigen::MatrixXd& J : *jacobians) J.setZero();
    return true;
  }
  const double sqrt_rho1 = std::sqrt(rho[1]);
  if (s == 0.0 || rho[2] <= 0.0) {
    *r *= sqrt_rho1;
    for (Eigen::MatrixXd& J : *jacobians) J *= sqrt_rho1;
    return true;
  }
  const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * s * rho[2] / rho[1]);
  const double alpha_over_s = alpha / s;
  for (Eigen::MatrixXd& J : *jacobians) {
    const Eigen::RowVectorXd rT_J = r->transpose() * J;
    J = sqrt_rho1 * (J - alpha_over_s * (*r) * rT_J);
  }
  *r *= sqrt_rho1 / (1.0 - alpha);
  return true;
}

// Evaluates one residual block at the current values: the residual and each
// block's tangent Jacobian (factors/term_linearizer.h), with the loss applied.
Status Linearize(const MarginalizationResidualBlock& residual_block,
                 const std::vector<const Block*>& blocks,
                 Eigen::VectorXd* r,
                 std::vector<Eigen::MatrixXd>* tangent_jacobians) {
  std::vector<const ceres::Manifold*> manifolds;
  manifolds.reserve(blocks.size());
  for (const Block* block : blocks) manifolds.push_back(block->manifold);
  SWARMLIO_RETURN_IF_ERROR(LinearizeTerm(*residual_block.cost_function,
                                         residual_block.parameter_blocks.data(), manifolds, r,
                                         tangent_jacobians));
  if (residual_block.loss_function != nullptr) {
    if (!ApplyLoss(*residual_block.loss_function, r, tangent_jacobians) || !r->allFinite()) {
      return Status::FailedPrecondition("the loss function is not finite");
    }
  }
  return Status::Ok();
}

// Adds the blocks of `list` to `blocks` / `index`; InvalidArgument on an empty
// list or a null or repeated block.
Status RegisterBlocks(const std::vector<double*>& list,
                      bool kept,
                      const char* name,
                      std::vector<Block>* blocks,
                      std::unordered_map<const double*, int>* index) {
  if (list.empty()) return Status::InvalidArgument(std::string("no ") + name + " blocks");
  for (double* values : list) {
    if (values == nullptr) return Status::InvalidArgument(std::string("null ") + name + " block");
    if (!index->emplace(values, static_cast<int>(blocks->size())).second) {
      return Status::InvalidArgument(std::string("a ") + name +
                                     " block is repeated or both kept and marginalized");
    }
    Block block;
    block.values = values;
    block.kept = kept;
    blocks->push_back(block);
  }
  return Status::Ok();
}

// Each residual's blocks (slots in `blocks`), with consistent sizes and
// manifolds; fills in each block's size and manifold from its first residual.
Status ResolveResidualBlocks(const std::vector<MarginalizationResidualBlock>& residual_blocks,
                             const std::unordered_map<const double*, int>& index,
                             std::vector<Block>* blocks,
                             std::vector<std::vector<int>>* residual_slots) {
  residual_slots->assign(residual_blocks.size(), {});
  for (size_t r = 0; r < residual_blocks.size(); ++r) {
    const MarginalizationResidualBlock& rb = residual_blocks[r];
    const std::vector<int32_t>& sizes = rb.cost_function->parameter_block_sizes();
    bool touches_marginalized = false;
    for (size_t i = 0; i < rb.parameter_blocks.size(); ++i) {
      const auto it = index.find(rb.parameter_blocks[i]);
      if (it == index.end()) {
        return Status::InvalidArgument(ResidualName(r) + ": parameter block " + std::to_string(i) +
                                       " is neither kept nor marginalized");
      }
      Block& block = (*blocks)[it->second];
      if (!block.touched) {
        block.touched = true;
        block.ambient = sizes[i];
        block.manifold = rb.manifolds[i];
        block.tangent = block.manifold == nullptr ? sizes[i] : block.manifold->TangentSize();
      } else if (block.ambient != sizes[i] || block.manifold != rb.manifolds[i]) {
        return Status::InvalidArgument(ResidualName(r) + ": parameter block " + std::to_string(i) +
                                       " has another size or manifold than in an earlier residual");
      }
      touches_marginalized = touches_marginalized || !block.kept;
      (*residual_slots)[r].push_back(it->second);
    }
    if (!touches_marginalized) {
      return Status::InvalidArgument(ResidualName(r) +
                                     " touches no marginalized block (it belongs in the window)");
    }
  }
  return Status::Ok();
}

// Each block's offset in the tangent system; *dim: its size, *kept_dim: the
// size of its kept part (the leading blocks).
Status AssignOffsets(std::vector<Block>* blocks, int* dim, int* kept_dim) {
  *dim = 0;
  *kept_dim = 0;
  for (Block& block : *blocks) {
    if (!block.touched) {
      return Status::InvalidArgument(std::string("a ") + (block.kept ? "kept" : "marginalized") +
                                     " block is in no residual block");
    }
    block.offset = *dim;
    *dim += block.tangent;
    if (block.kept) *kept_dim = *dim;
  }
  return Status::Ok();
}

// H = sum J^T J, b = sum J^T r in the tangent space, each residual evaluated once.
Status NormalEquations(const std::vector<MarginalizationResidualBlock>& residual_blocks,
                       const std::vector<Block>& blocks,
                       const std::vector<std::vector<int>>& residual_slots,
                       int dim,
                       Eigen::MatrixXd* H_out,
                       Eigen::VectorXd* b_out) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(dim);
  Eigen::VectorXd residual;
  std::vector<Eigen::MatrixXd> J;
  for (size_t r = 0; r < residual_blocks.size(); ++r) {
    std::vector<const Block*> rb_blocks;
    for (int slot : residual_slots[r]) rb_blocks.push_back(&blocks[slot]);
    SWARMLIO_RETURN_IF_ERROR(
        Linearize(residual_blocks[r], rb_blocks, &residual, &J).WithContext(ResidualName(r)));
    for (size_t i = 0; i < rb_blocks.size(); ++i) {
      const Block& bi = *rb_blocks[i];
      b.segment(bi.offset, bi.tangent).noalias() += J[i].transpose() * residual;
      for (size_t j = 0; j < rb_blocks.size(); ++j) {
        const Block& bj = *rb_blocks[j];
        H.block(bi.offset, bj.offset, bi.tangent, bj.tangent).noalias() += J[i].transpose() * J[j];
      }
    }
  }
  *H_out = std::move(H);
  *b_out = std::move(b);
  return Status::Ok();
}

// Schur complement with H_mm^+ = V_s diag(1/l_s) V_s^T (l_s: the eigenvalues above
// the threshold): W = H_km V_s diag(1/sqrt(l_s)), H* = H_kk - W W^T (symmetric by
// construction), b* = b_k - W diag(1/sqrt(l_s)) V_s^T b_m. Fills the prior's
// information, gradient, marginalized_dim and marginalized_rank.
Status SchurComplement(const Eigen::MatrixXd& H,
                       const Eigen::VectorXd& b,
                       int kept_dim,
                       int marginalized_dim,
                       double min_relative_eigenvalue,
                       MarginalizationPrior* out) {
  const Eigen::MatrixXd H_mm =
      0.5 * (H.bottomRightCorner(marginalized_dim, marginalized_dim) +
             H.bottomRightCorner(marginalized_dim, marginalized_dim).transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H_mm);
  if (eig.info() != Eigen::Success) {
    return Status::FailedPrecondition("eigen-decomposition of H_mm failed");
  }
  const Eigen::VectorXd& l = eig.eigenvalues();
  const double threshold = min_relative_eigenvalue * std::max(l.maxCoeff(), 0.0);
  std::vector<int> used;
  for (int k = 0; k < marginalized_dim; ++k) {
    if (l[k] > threshold && l[k] > 0.0) used.push_back(k);
  }
  const int rank = static_cast<int>(used.size());
  Eigen::MatrixXd U(marginalized_dim, rank);  // V_s diag(1/sqrt(l_s))
  for (int c = 0; c < rank; ++c) {
    U.col(c) = eig.eigenvectors().col(used[c]) / std::sqrt(l[used[c]]);
  }
  const Eigen::MatrixXd W = H.topRightCorner(kept_dim, marginalized_dim) * U;
  const Eigen::VectorXd u = U.transpose() * b.tail(marginalized_dim);

  out->information = H.topLeftCorner(kept_dim, kept_dim) - W * W.transpose();
  out->information = 0.5 * (out->information + out->information.transpose());
  out->gradient = b.head(kept_dim) - W * u;
  out->marginalized_dim = marginalized_dim;
  out->marginalized_rank = rank;
  return Status::Ok();
}

}  // namespace

Status Marginalizer::Create(const MarginalizationOptions& options,
                            std::unique_ptr<Marginalizer>* marginalizer) {
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument(error);
  marginalizer->reset(new Marginalizer(options));
  return Status::Ok();
}

Status Marginalizer::AddResidualBlock(const MarginalizationResidualBlock& block) {
  if (block.cost_function == nullptr) return Status::InvalidArgument("null cost function");
  if (block.cost_function->num_residuals() <= 0) {
    return Status::InvalidArgument("the cost function has no residuals");
  }
  const std::vector<int32_t>& sizes = block.cost_function->parameter_block_sizes();
  if (block.parameter_blocks.size() != sizes.size() || block.manifolds.size() != sizes.size()) {
    return Status::InvalidArgument("the cost function has " + std::to_string(sizes.size()) +
                                   " parameter blocks, given " +
                                   std::to_string(block.parameter_blocks.size()) + " blocks and " +
                                   std::to_string(block.manifolds.size()) + " manifolds");
  }
  for (size_t i = 0; i < sizes.size(); ++i) {
    if (block.parameter_blocks[i] == nullptr) {
      return Status::InvalidArgument("parameter block " + std::to_string(i) + " is null");
    }
    for (size_t j = 0; j < i; ++j) {
      if (block.parameter_blocks[j] == block.parameter_blocks[i]) {
        return Status::InvalidArgument("parameter block " + std::to_string(i) + " is repeated");
      }
    }
    const ceres::Manifold* manifold = block.manifolds[i];
    if (manifold != nullptr && manifold->AmbientSize() != sizes[i]) {
      return Status::InvalidArgument("parameter block " + std::to_string(i) + " has size " +
                                     std::to_string(sizes[i]) + ", its manifold ambient size " +
                                     std::to_string(manifold->AmbientSize()));
    }
  }
  residual_blocks_.push_back(block);
  return Status::Ok();
}

Status Marginalizer::Marginalize(const std::vector<double*>& marginalized,
                                 const std::vector<double*>& kept,
                                 MarginalizationPrior* prior) const {
  if (residual_blocks_.empty()) return Status::InvalidArgument("no residual blocks");
  // Blocks in system order: kept first, then marginalized.
  std::vector<Block> blocks;
  std::unordered_map<const double*, int> index;
  SWARMLIO_RETURN_IF_ERROR(RegisterBlocks(kept, true, "kept", &blocks, &index));
  SWARMLIO_RETURN_IF_ERROR(RegisterBlocks(marginalized, false, "marginalized", &blocks, &index));

  // Each residual's blocks, with consistent sizes and manifolds.
  std::vector<std::vector<int>> residual_slots;
  SWARMLIO_RETURN_IF_ERROR(
      ResolveResidualBlocks(residual_blocks_, index, &blocks, &residual_slots));
  int dim = 0;
  int kept_dim = 0;
  SWARMLIO_RETURN_IF_ERROR(AssignOffsets(&blocks, &dim, &kept_dim));
  const int marginalized_dim = dim - kept_dim;

  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  SWARMLIO_RETURN_IF_ERROR(NormalEquations(residual_blocks_, blocks, residual_slots, dim, &H, &b));
  MarginalizationPrior out;
  SWARMLIO_RETURN_IF_ERROR(
      SchurComplement(H, b, kept_dim, marginalized_dim, options_.min_relative_eigenvalue, &out));
  for (const Block& block : blocks) {
    if (!block.kept) continue;
    out.parameter_blocks.push_back(block.values);
    out.linearization_points.push_back(
        Eigen::Map<const Eigen::VectorXd>(block.values, block.ambient));
    out.manifolds.push_back(block.manifold);
    out.ambient_sizes.push_back(block.ambient);
    out.tangent_sizes.push_back(block.tangent);
  }
  *prior = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::window
