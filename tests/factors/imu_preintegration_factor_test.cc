// ImuPreintegrationFactor's manifold Jacobians (fixture:
// imu_preintegration_test_fixture.h): against numeric differentiation at
// random, near-identity and near-pi rotations, the check rejecting flipped
// signs, the whitening, and evaluation without Jacobians.
#include "imu_preintegration_test_fixture.h"

namespace swarmlio {
namespace {

using namespace imu_preintegration_test;  // NOLINT(build/namespaces): the fixture

// --- (a), (b) manifold Jacobians ------------------------------------------

TEST(ImuPreintegrationFactor, Sizes) {
  Sampler s(7);
  const Problem pr(&s, -1.0, kNear);
  const auto factor = MakeFactor(pr.preintegrated);
  EXPECT_EQ(factor->num_residuals(), 18);
  EXPECT_EQ(factor->parameter_block_sizes(), (std::vector<int32_t>{19, 19}));
}

TEST(ImuPreintegrationFactor, JacobianIsCorrectAtRandomNearIdentityAndNearPiRotations) {
  Sampler s(8);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  // x_k's rotation at each angle, then x_k+1's (the other one near it).
  for (const bool vary_k : {true, false}) {
    for (double angle : angles) {
      SCOPED_TRACE(::testing::Message() << (vary_k ? "x_k " : "x_k+1 ") << angle);
      for (int trial = 0; trial < 3; ++trial) {
        const Problem pr(&s, vary_k ? angle : kNear, vary_k ? kNear : angle);
        const auto factor = MakeFactor(pr.preintegrated);
        const Blocks b(pr.x_k, pr.x_k1);
        EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, b.manifolds(), b.pointers()));
      }
    }
  }
  // Independent rotations: a large rotation residual. Log is not
  // differentiable at pi (the shortest rotation flips), so residuals within
  // 0.2 rad of pi are not probed.
  int checked = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Problem pr(&s, -1.0, -1.0);
    const auto factor = MakeFactor(pr.preintegrated);
    if (factor->Error(pr.x_k, pr.x_k1).head<3>().norm() > M_PI - 0.2) continue;
    const Blocks b(pr.x_k, pr.x_k1);
    EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, b.manifolds(), b.pointers()))
        << "trial " << trial;
    ++checked;
  }
  EXPECT_GE(checked, 8);
}

TEST(ImuPreintegrationFactor, FlippedColumnsAreRejected) {
  Sampler s(9);
  const Problem pr(&s, -1.0, kNear);
  const auto factor = MakeFactor(pr.preintegrated);
  const Blocks b(pr.x_k, pr.x_k1);
  ASSERT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, b.manifolds(), b.pointers()));
  using testing::FlippedJacobianColumns;
  // Ambient columns: q 0..3, p 4..6, v 7..9, b_g 10..12, b_a 13..15, g 16..18.
  const FlippedJacobianColumns flips[] = {
      {factor.get(), /*block=*/0, /*num_columns=*/4},  // rotation k
      {factor.get(), 0, 3, /*first_column=*/7},        // velocity k
      {factor.get(), 0, 3, 10},                        // gyro bias k
      {factor.get(), 0, 3, 16},                        // gravity k
      {factor.get(), 1, 4},                            // rotation k+1
      {factor.get(), 1, 3, 4},                         // position k+1
  };
  for (size_t i = 0; i < std::size(flips); ++i) {
    EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(flips[i], b.manifolds(), b.pointers()))
        << "flip " << i;
  }
}

TEST(ImuPreintegrationFactor, TangentJacobianMatchesNumericDifferentiation) {
  Sampler s(10);
  for (double angle : {-1.0, M_PI - 1e-3, 1e-9}) {
    SCOPED_TRACE(angle);
    const Problem pr(&s, angle, kNear);
    const auto factor = MakeFactor(pr.preintegrated);
    Matrix18 J_k, J_k1;
    factor->TangentJacobian(pr.x_k, pr.x_k1, &J_k, &J_k1);
    Eigen::Matrix<double, 18, 36> J;
    J << J_k, J_k1;
    const Eigen::MatrixXd numeric = testing::NumericJacobian(
        [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
          return factor->Residual(pr.x_k.BoxPlus(dx.head<18>()), pr.x_k1.BoxPlus(dx.tail<18>()));
        },
        36, 1e-7);
    const double scale = J.cwiseAbs().maxCoeff();
    EXPECT_TRUE(testing::MatricesNear(J / scale, numeric / scale, 1e-7, 1e-7));
  }
}

TEST(ImuPreintegrationFactor, WhitenedResidualIsTheMahalanobisDistance) {
  Sampler s(11);
  for (int trial = 0; trial < 5; ++trial) {
    const Problem pr(&s, -1.0, -1.0);
    const auto factor = MakeFactor(pr.preintegrated);
    const Vector18 e = factor->Error(pr.x_k, pr.x_k1);
    const Vector18 r = factor->Residual(pr.x_k, pr.x_k1);
    const double mahalanobis = e.dot(pr.preintegrated.covariance.ldlt().solve(e));
    EXPECT_NEAR(r.squaredNorm(), mahalanobis, 1e-8 * mahalanobis);
    const Matrix18& W = factor->sqrt_information();
    EXPECT_EQ(W.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0);
    EXPECT_LT((W * pr.preintegrated.covariance * W.transpose() - Matrix18::Identity()).norm(),
              1e-8);
    // The error is the header's definition.
    const Eigen::Matrix3d R_k = pr.x_k.R_G_b();
    const double T = pr.preintegrated.dt_s;
    const Eigen::Vector3d bg = pr.x_k.gyro_bias, ba = pr.x_k.accel_bias;
    Vector18 expected;
    expected << so3::Log(pr.preintegrated.CorrectedDeltaR(bg).transpose() * R_k.transpose() *
                         pr.x_k1.R_G_b()),
        R_k.transpose() * (pr.x_k1.p_b_in_G - pr.x_k.p_b_in_G - pr.x_k.v_b_in_G * T -
                           0.5 * T * T * pr.x_k.g_in_G) -
            pr.preintegrated.CorrectedDeltaP(bg, ba),
        R_k.transpose() * (pr.x_k1.v_b_in_G - pr.x_k.v_b_in_G - T * pr.x_k.g_in_G) -
            pr.preintegrated.CorrectedDeltaV(bg, ba),
        pr.x_k1.gyro_bias - bg, pr.x_k1.accel_bias - ba, pr.x_k1.g_in_G - pr.x_k.g_in_G;
    EXPECT_LT((e - expected).norm(), 1e-12 * (1.0 + expected.norm()));
  }
}

TEST(ImuPreintegrationFactor, ResidualsWithoutJacobianMatchFullEvaluation) {
  Sampler s(12);
  const Problem pr(&s, -1.0, -1.0);
  const auto factor = MakeFactor(pr.preintegrated);
  const Blocks b(pr.x_k, pr.x_k1);
  const std::vector<const double*> p = b.pointers();
  Vector18 r1, r2, r3;
  std::array<double, 18 * 19> j_k, j_k1;
  double* none[] = {nullptr, nullptr};
  double* only_k1[] = {nullptr, j_k1.data()};
  double* both[] = {j_k.data(), j_k1.data()};
  ASSERT_TRUE(factor->Evaluate(p.data(), r1.data(), nullptr));
  ASSERT_TRUE(factor->Evaluate(p.data(), r2.data(), none));
  ASSERT_TRUE(factor->Evaluate(p.data(), r3.data(), only_k1));
  EXPECT_EQ(r1, r2);
  EXPECT_EQ(r1, r3);
  ASSERT_TRUE(factor->Evaluate(p.data(), r3.data(), both));
  EXPECT_EQ(r1, r3);
}

}  // namespace
}  // namespace swarmlio
