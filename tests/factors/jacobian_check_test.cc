// The Jacobian-check helper must pass a correct analytic Jacobian and FAIL a
// deliberately wrong one (sign flipped, or a column missing).
#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include "factors/global_extrinsic_manifold.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"

namespace swarmlio {
namespace {

// r = R_Gi_Gj a + p_Gj_in_Gi - b over one GlobalExtrinsic block (7 ambient).
// Tangent Jacobian: d r / d dtheta = -R [a]x, d r / d dp = I.
class TransformPointCost final : public ceres::SizedCostFunction<3, 7> {
 public:
  enum class Mode { kCorrect, kFlippedRotationSign, kMissingTranslation };
  TransformPointCost(Eigen::Vector3d a, Eigen::Vector3d b, Mode mode)
      : a_(std::move(a)), b_(std::move(b)), mode_(mode) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const GlobalExtrinsic T = GlobalExtrinsic::FromParameters(parameters[0]);
    const Eigen::Matrix3d R = T.R_Ga_Gb();
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = R * a_ + T.p_Gb_in_Ga - b_;
    if (jacobians == nullptr || jacobians[0] == nullptr) return true;
    Eigen::Matrix3d J_rot = -R * so3::Hat(a_);
    if (mode_ == Mode::kFlippedRotationSign) J_rot = -J_rot;
    Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>> J(jacobians[0]);
    J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<3>(J_rot, parameters[0]);
    J.rightCols<3>().setIdentity();
    if (mode_ == Mode::kMissingTranslation) J.rightCols<3>().setZero();
    return true;
  }

 private:
  Eigen::Vector3d a_, b_;
  Mode mode_;
};

class JacobianCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    GlobalExtrinsic T;
    T.q_Ga_Gb = so3::ExpQuaternion(Eigen::Vector3d(0.3, -1.1, 0.7));
    T.p_Gb_in_Ga = Eigen::Vector3d(1.0, 2.0, -0.5);
    T.ToParameters(x_);
  }
  bool Check(TransformPointCost::Mode mode) {
    const TransformPointCost cost(Eigen::Vector3d(0.4, -2.0, 1.5), Eigen::Vector3d(1, 1, 1), mode);
    return testing::CostFunctionJacobiansAreCorrect(cost, {&manifold_}, {x_});
  }
  GlobalExtrinsicManifold manifold_;
  double x_[7];
};

TEST_F(JacobianCheckTest, AcceptsTheCorrectJacobian) {
  EXPECT_TRUE(Check(TransformPointCost::Mode::kCorrect));
}

TEST_F(JacobianCheckTest, RejectsAFlippedSign) {
  EXPECT_FALSE(Check(TransformPointCost::Mode::kFlippedRotationSign));
}

TEST_F(JacobianCheckTest, RejectsAMissingBlock) {
  EXPECT_FALSE(Check(TransformPointCost::Mode::kMissingTranslation));
}

TEST(NumericJacobian, RejectsWrongAnalyticJacobian) {
  const auto f = [](const Eigen::VectorXd& d) -> Eigen::VectorXd {
    return Eigen::Vector2d(std::sin(d[0]) + 2 * d[1], d[0] * d[1]);
  };
  Eigen::Matrix2d J;
  J << 1, 2, 0, 0;
  EXPECT_TRUE(testing::MatricesNear(J, testing::NumericJacobian(f, 2), 1e-8));
  J(0, 1) = -2;
  EXPECT_FALSE(testing::MatricesNear(J, testing::NumericJacobian(f, 2), 1e-8));
}

}  // namespace
}  // namespace swarmlio
