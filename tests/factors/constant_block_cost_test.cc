// ConstantBlockCost (factors/constant_block_cost.h): a cost with one block
// held at a value. Its residuals and Jacobians are the wrapped
// cost's with the held block at its value; GradientChecker on the remaining
// blocks.
#include "factors/constant_block_cost.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

namespace swarmlio {
namespace {

// r = (a0 * b1 - c0, a1 + b0 * c1): three blocks of size 2, all coupled.
struct Coupled {
  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, T* r) const {
    r[0] = a[0] * b[1] - c[0];
    r[1] = a[1] + b[0] * c[1];
    return true;
  }
};

std::unique_ptr<ceres::CostFunction> MakeCoupled() {
  return std::make_unique<ceres::AutoDiffCostFunction<Coupled, 2, 2, 2, 2>>(new Coupled);
}

TEST(ConstantBlockCost, EqualsTheWrappedCostWithTheBlockHeld) {
  const std::array<double, 2> a{0.3, -1.2}, b{2.0, 0.7}, c{-0.4, 1.5};
  const std::array<double, 2> b_held{-3.0, 0.25};
  ConstantBlockCost cost(MakeCoupled(), 1, {b_held[0], b_held[1]});
  ASSERT_EQ(cost.parameter_block_sizes().size(), 2u);
  ASSERT_EQ(cost.num_residuals(), 2);

  std::array<double, 2> r{}, r_inner{};
  std::array<double, 4> J_a{}, J_c{}, J_inner_a{}, J_inner_b{}, J_inner_c{};
  const double* outer[] = {a.data(), c.data()};
  double* outer_jac[] = {J_a.data(), J_c.data()};
  ASSERT_TRUE(cost.Evaluate(outer, r.data(), outer_jac));
  const auto inner = MakeCoupled();
  const double* inner_params[] = {a.data(), b_held.data(), c.data()};
  double* inner_jac[] = {J_inner_a.data(), J_inner_b.data(), J_inner_c.data()};
  ASSERT_TRUE(inner->Evaluate(inner_params, r_inner.data(), inner_jac));
  EXPECT_EQ(r, r_inner);
  EXPECT_EQ(J_a, J_inner_a);
  EXPECT_EQ(J_c, J_inner_c);
  // The block passed in is ignored: b (not b_held) would change the residual.
  const double* with_b[] = {a.data(), b.data(), c.data()};
  std::array<double, 2> r_b{};
  ASSERT_TRUE(inner->Evaluate(with_b, r_b.data(), nullptr));
  EXPECT_NE(r, r_b);

  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&cost, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(outer, 1e-8, &results)) << results.error_log;
}

TEST(ConstantBlockCost, HoldsTheFirstOrTheLastBlock) {
  const std::array<double, 2> a{0.3, -1.2}, b{2.0, 0.7}, c{-0.4, 1.5};
  for (int held : {0, 2}) {
    const std::array<double, 2>& value = held == 0 ? a : c;
    ConstantBlockCost cost(MakeCoupled(), held, {value[0], value[1]});
    const double* outer[] = {held == 0 ? b.data() : a.data(), held == 0 ? c.data() : b.data()};
    std::array<double, 2> r{}, r_inner{};
    ASSERT_TRUE(cost.Evaluate(outer, r.data(), nullptr));
    const double* inner_params[] = {a.data(), b.data(), c.data()};
    ASSERT_TRUE(MakeCoupled()->Evaluate(inner_params, r_inner.data(), nullptr));
    EXPECT_EQ(r, r_inner) << "held block " << held;
  }
}

}  // namespace
}  // namespace swarmlio
