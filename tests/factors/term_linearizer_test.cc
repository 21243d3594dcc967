#include "factors/term_linearizer.h"

#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <vector>

#include "factors/ego_state_manifold.h"
#include "factors/relative_pose_factor.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "test_utils/random_sampler.h"

namespace swarmlio {
namespace {

using Matrix6 = RelativePoseFactor::Matrix6;
using Ambient = std::array<double, EgoState::kAmbientSize>;

EgoState RandomEgo(testing::RandomSampler* s) {
  EgoState ego;
  ego.q_G_b = s->Rotation(-1.0);
  ego.p_b_in_G = s->Gaussian3(5.0);
  ego.v_b_in_G = s->Gaussian3(1.0);
  ego.gyro_bias = s->Gaussian3(0.01);
  ego.accel_bias = s->Gaussian3(0.1);
  ego.g_in_G = 9.81 * s->Gaussian3(1.0).normalized();
  return ego;
}

// A relative pose measurement between two random states, off the true one.
RelativePoseFactor RandomFactor(testing::RandomSampler* s, const EgoState& a, const EgoState& b) {
  const Eigen::Matrix3d R_a_b = a.R_G_b().transpose() * b.R_G_b();
  const Eigen::Vector3d p_b_in_a = a.R_G_b().transpose() * (b.p_b_in_G - a.p_b_in_G);
  Matrix6 A;
  for (int i = 0; i < 36; ++i) A.data()[i] = 0.05 * s->Normal();
  const Matrix6 covariance = A * A.transpose() + 1e-3 * Matrix6::Identity();
  return RelativePoseFactor(Eigen::Quaterniond(R_a_b * so3::Exp(s->Gaussian3(0.1))),
                            p_b_in_a + s->Gaussian3(0.3),
                            RelativePoseFactor::SqrtInformationOfCovariance(covariance));
}

// The residual with block `block` moved to x (+) d on `manifold` (nullptr:
// x + d), the other block at its value.
Eigen::VectorXd ResidualAt(const ceres::CostFunction& cost, const ceres::Manifold* manifold,
                           const std::array<Ambient, 2>& x, int block, const Eigen::VectorXd& d) {
  std::array<Ambient, 2> moved = x;
  if (manifold != nullptr) {
    manifold->Plus(x[block].data(), d.data(), moved[block].data());
  } else {
    for (int k = 0; k < d.size(); ++k) moved[block][k] += d[k];
  }
  const double* parameters[] = {moved[0].data(), moved[1].data()};
  Eigen::VectorXd r(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(parameters, r.data(), nullptr));
  return r;
}

// Each block's tangent Jacobian against central differences of the residual
// on the block's manifold (or the ambient space for a Euclidean block).
void ExpectTangentJacobiansMatchNumeric(const ceres::Manifold* second_manifold) {
  testing::RandomSampler s(7);
  EgoStateManifold ego_manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const EgoState a = RandomEgo(&s);
    const EgoState b = RandomEgo(&s);
    const RelativePoseFactor factor = RandomFactor(&s, a, b);
    std::array<Ambient, 2> x;
    a.ToParameters(x[0].data());
    b.ToParameters(x[1].data());
    const std::vector<const ceres::Manifold*> manifolds = {&ego_manifold, second_manifold};
    const double* parameters[] = {x[0].data(), x[1].data()};
    Eigen::VectorXd r;
    std::vector<Eigen::MatrixXd> J;
    ASSERT_TRUE(LinearizeTerm(factor, parameters, manifolds, &r, &J).ok());
    ASSERT_EQ(J.size(), 2u);
    EXPECT_TRUE(r.isApprox(ResidualAt(factor, nullptr, x, 0, Eigen::VectorXd::Zero(19))));
    for (int block = 0; block < 2; ++block) {
      const ceres::Manifold* m = manifolds[static_cast<size_t>(block)];
      const int n = m != nullptr ? m->TangentSize() : EgoState::kAmbientSize;
      ASSERT_EQ(J[static_cast<size_t>(block)].cols(), n);
      const Eigen::MatrixXd numeric = testing::NumericJacobian(
          [&](const Eigen::VectorXd& d) { return ResidualAt(factor, m, x, block, d); }, n);
      EXPECT_TRUE(testing::MatricesNear(J[static_cast<size_t>(block)], numeric, 1e-6, 1e-6))
          << "block " << block << ", trial " << trial;
    }
  }
}

TEST(LinearizeTerm, TangentJacobiansMatchNumericDifferentiationOnTheManifold) {
  EgoStateManifold ego_manifold;
  ExpectTangentJacobiansMatchNumeric(&ego_manifold);
}

TEST(LinearizeTerm, AEuclideanBlockKeepsItsAmbientJacobian) {
  ExpectTangentJacobiansMatchNumeric(nullptr);
}

// The control: with the sign of the rotation's ambient columns flipped, the
// same comparison fails.
TEST(LinearizeTerm, AFlippedAmbientColumnIsCaught) {
  testing::RandomSampler s(11);
  EgoStateManifold ego_manifold;
  const EgoState a = RandomEgo(&s);
  const EgoState b = RandomEgo(&s);
  const RelativePoseFactor factor = RandomFactor(&s, a, b);
  const testing::FlippedJacobianColumns flipped(&factor, 0, 4);
  std::array<Ambient, 2> x;
  a.ToParameters(x[0].data());
  b.ToParameters(x[1].data());
  const double* parameters[] = {x[0].data(), x[1].data()};
  Eigen::VectorXd r;
  std::vector<Eigen::MatrixXd> J;
  ASSERT_TRUE(LinearizeTerm(flipped, parameters, {&ego_manifold, &ego_manifold}, &r, &J).ok());
  const Eigen::MatrixXd numeric = testing::NumericJacobian(
      [&](const Eigen::VectorXd& d) { return ResidualAt(factor, &ego_manifold, x, 0, d); },
      ego_manifold.TangentSize());
  EXPECT_FALSE(testing::MatricesNear(J[0], numeric, 1e-6, 1e-6));
}

// A cost that fails, or returns a non-finite residual, on request.
class BadCost final : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit BadCost(bool fail) : fail_(fail) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (fail_) return false;
    residuals[0] = std::numeric_limits<double>::quiet_NaN() * parameters[0][0];
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = 1.0;
    return true;
  }

 private:
  bool fail_;
};

TEST(LinearizeTerm, RefusesAFailedOrNonFiniteEvaluation) {
  const double value = 1.0;
  const double* parameters[] = {&value};
  Eigen::VectorXd r;
  std::vector<Eigen::MatrixXd> J;
  const Status failed = LinearizeTerm(BadCost(true), parameters, {nullptr}, &r, &J);
  EXPECT_EQ(failed.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(failed.message().find("failed to evaluate"), std::string::npos);
  const Status nan = LinearizeTerm(BadCost(false), parameters, {nullptr}, &r, &J);
  EXPECT_EQ(nan.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(nan.message().find("not finite"), std::string::npos);
  EXPECT_EQ(LinearizeTerm(BadCost(false), parameters, {}, &r, &J).code(),
            Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio
