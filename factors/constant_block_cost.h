// ConstantBlockCost: a cost function with one of its parameter blocks held
// at a fixed value c. For an inner cost r(x_0, ..., x_b, ..., x_n) it is
//
//   r'(x_0, ..., x_{b-1}, x_{b+1}, ..., x_n) = r(x_0, ..., c, ..., x_n),
//   dr'/dx_k = dr/dx_k (k != b),
//
// so the residual does not depend on x_b and x_b's uncertainty never enters
// the problem. Uses: the degeneracy policy freeze_extrinsics (T_Gi_Gj an exact
// constant of the mutual observations, docs/swarm.md section 7) and the
// window smoother's form of a considered teammate block (docs/window.md).
#pragma once

#include <ceres/cost_function.h>

#include <memory>
#include <utility>
#include <vector>

namespace swarmlio {

class ConstantBlockCost final : public ceres::CostFunction {
 public:
  /// `block`: the index of the fixed block among inner's; `value`: its
  /// parameters (inner's size of that block).
  ConstantBlockCost(std::unique_ptr<ceres::CostFunction> inner, int block,
                    std::vector<double> value)
      : inner_(std::move(inner)), block_(block), value_(std::move(value)) {
    set_num_residuals(inner_->num_residuals());
    const std::vector<int32_t>& sizes = inner_->parameter_block_sizes();
    for (int b = 0; b < static_cast<int>(sizes.size()); ++b) {
      if (b != block_) mutable_parameter_block_sizes()->push_back(sizes[static_cast<size_t>(b)]);
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const size_t n = inner_->parameter_block_sizes().size();
    std::vector<const double*> blocks(n);
    std::vector<double*> inner_jacobians(n, nullptr);
    for (size_t b = 0, k = 0; b < n; ++b) {
      if (static_cast<int>(b) == block_) {
        blocks[b] = value_.data();
      } else {
        blocks[b] = parameters[k];
        if (jacobians != nullptr) inner_jacobians[b] = jacobians[k];
        ++k;
      }
    }
    return inner_->Evaluate(blocks.data(), residuals,
                            jacobians != nullptr ? inner_jacobians.data() : nullptr);
  }

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  int block_;
  std::vector<double> value_;
};

}  // namespace swarmlio
