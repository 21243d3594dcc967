// RelativePoseFactor: a measured T_a_b between two ego states. Checks the
// residual against its definition through Eigen's isometries (zero at the
// measured pose, the Mahalanobis distance elsewhere), the analytic manifold
// Jacobians (random, near-identity and near-pi attitudes, small and large
// errors), that flipped rotation and position columns of either state are
// rejected, the tangent Jacobian against the header's formulas and numeric
// differentiation, and the square-root information of a covariance.
#include "factors/relative_pose_factor.h"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "factors/ego_state_manifold.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "test_utils/state_sampler.h"

namespace swarmlio {
namespace {

using Matrix6 = RelativePoseFactor::Matrix6;

using Sampler = swarmlio::testing::StateSampler;

Eigen::Isometry3d Pose(const EgoState& ego) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ego.R_G_b();
  T.translation() = ego.p_b_in_G;
  return T;
}

// Two states and a measurement of their relative pose, off the true one by
// a rotation of about `error_rad` and a translation of about `error_m`.
struct Problem {
  EgoState a;
  EgoState b;
  Eigen::Isometry3d T_a_b_measured;
  Matrix6 covariance;

  Problem(Sampler* s, double angle_a, double angle_b, double error_rad, double error_m)
      : a(s->Ego(angle_a)), b(s->Ego(angle_b)), covariance(s->Covariance(6, 0.05, 1e-3)) {
    const Eigen::Isometry3d T_a_b = Pose(a).inverse() * Pose(b);
    T_a_b_measured = T_a_b;
    T_a_b_measured.linear() = T_a_b.linear() * so3::Exp(s->Gaussian3(error_rad));
    T_a_b_measured.translation() += s->Gaussian3(error_m);
  }
  RelativePoseFactor Factor() const {
    return RelativePoseFactor(Eigen::Quaterniond(T_a_b_measured.linear()),
                              T_a_b_measured.translation(),
                              RelativePoseFactor::SqrtInformationOfCovariance(covariance));
  }
};

struct Blocks {
  Blocks(const EgoState& a, const EgoState& b) {
    a.ToParameters(x_a.data());
    b.ToParameters(x_b.data());
  }
  std::vector<const double*> pointers() const { return {x_a.data(), x_b.data()}; }
  std::vector<const ceres::Manifold*> manifolds() const { return {&manifold, &manifold}; }
  std::array<double, EgoState::kAmbientSize> x_a;
  std::array<double, EgoState::kAmbientSize> x_b;
  EgoStateManifold manifold;
};

TEST(RelativePoseFactor, ZeroAtTheMeasuredPoseAndTheMahalanobisDistanceElsewhere) {
  Sampler s(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem exact(&s, -1.0, -1.0, 0.0, 0.0);
    EXPECT_NEAR(exact.Factor().Residual(exact.a, exact.b).norm(), 0.0, 1e-9);
    const Problem pr(&s, -1.0, -1.0, 0.1, 0.3);
    const RelativePoseFactor factor = pr.Factor();
    // The error through Eigen: estimated T_a_b against the measured one.
    const Eigen::Isometry3d T_a_b = Pose(pr.a).inverse() * Pose(pr.b);
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() =
        so3::Log(Eigen::Matrix3d(pr.T_a_b_measured.linear().transpose() * T_a_b.linear()));
    e.tail<3>() = T_a_b.translation() - pr.T_a_b_measured.translation();
    const double m2 = e.dot(pr.covariance.ldlt().solve(e));
    const Blocks blocks(pr.a, pr.b);
    Eigen::Matrix<double, 6, 1> r;
    const std::vector<const double*> p = blocks.pointers();
    ASSERT_TRUE(factor.Evaluate(p.data(), r.data(), nullptr));
    EXPECT_NEAR(r.squaredNorm(), m2, 1e-9 * m2);
    EXPECT_TRUE(testing::MatricesNear(factor.Error(pr.a, pr.b), e, 1e-12, 1e-12));
  }
}

TEST(RelativePoseFactor, JacobianIsCorrectAtRandomNearIdentityAndNearPiAttitudes) {
  Sampler s(2);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  for (double angle_a : angles) {
    for (double angle_b : angles) {
      SCOPED_TRACE(::testing::Message() << "a " << angle_a << ", b " << angle_b);
      for (double error_rad : {0.0, 0.05, 1.0}) {
        const Problem pr(&s, angle_a, angle_b, error_rad, 0.5);
        const RelativePoseFactor factor = pr.Factor();
        const Blocks b(pr.a, pr.b);
        EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
      }
    }
  }
}

TEST(RelativePoseFactor, FlippedColumnsAreRejected) {
  Sampler s(3);
  const Problem pr(&s, -1.0, -1.0, 0.1, 0.3);
  const RelativePoseFactor factor = pr.Factor();
  const Blocks b(pr.a, pr.b);
  ASSERT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
  // Ambient ego columns: q 0-3, p 4-6, v 7-9, b_g 10-12, b_a 13-15, g 16-18.
  for (int block : {0, 1}) {
    SCOPED_TRACE(block);
    const testing::FlippedJacobianColumns rotation(&factor, block, /*num_columns=*/4);
    const testing::FlippedJacobianColumns position(&factor, block, /*num_columns=*/3,
                                                   /*first_column=*/4);
    EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(rotation, b.manifolds(), b.pointers()));
    EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(position, b.manifolds(), b.pointers()));
  }
}

TEST(RelativePoseFactor, TangentJacobianIsTheStatedFormulaAndNumeric) {
  Sampler s(4);
  for (int trial = 0; trial < 10; ++trial) {
    const Problem pr(&s, -1.0, -1.0, 0.2, 0.3);
    const RelativePoseFactor factor = pr.Factor();
    RelativePoseFactor::TangentJacobian6 J_a;
    RelativePoseFactor::TangentJacobian6 J_b;
    factor.TangentJacobian(pr.a, pr.b, &J_a, &J_b);
    // The header's formulas, unwhitened (L^-1 J).
    const Eigen::Matrix3d R_G_a = pr.a.R_G_b();
    const Eigen::Matrix3d Jr_inv = so3::RightJacobianInverse(factor.Error(pr.a, pr.b).head<3>());
    RelativePoseFactor::TangentJacobian6 H_a = RelativePoseFactor::TangentJacobian6::Zero();
    H_a.block<3, 3>(0, 0) = -Jr_inv * pr.b.R_G_b().transpose() * R_G_a;
    H_a.block<3, 3>(3, 0) = so3::Hat(R_G_a.transpose() * (pr.b.p_b_in_G - pr.a.p_b_in_G));
    H_a.block<3, 3>(3, 3) = -R_G_a.transpose();
    RelativePoseFactor::TangentJacobian6 H_b = RelativePoseFactor::TangentJacobian6::Zero();
    H_b.block<3, 3>(0, 0) = Jr_inv;
    H_b.block<3, 3>(3, 3) = R_G_a.transpose();
    const Matrix6 L_inv = factor.sqrt_information().inverse();
    EXPECT_TRUE(testing::MatricesNear(L_inv * J_a, H_a, 1e-10, 1e-10));
    EXPECT_TRUE(testing::MatricesNear(L_inv * J_b, H_b, 1e-10, 1e-10));
    Eigen::Matrix<double, 6, 36> J;
    J << J_a, J_b;
    const Eigen::MatrixXd numeric = testing::NumericJacobian(
        [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
          return factor.Residual(pr.a.BoxPlus(dx.head<18>()), pr.b.BoxPlus(dx.tail<18>()));
        },
        36);
    EXPECT_TRUE(testing::MatricesNear(J, numeric, 1e-6, 1e-7));
  }
}

TEST(RelativePoseFactor, SqrtInformationWhitensTheCovariance) {
  Sampler s(5);
  const Matrix6 C = s.Covariance(6, 0.05, 1e-3);
  const Matrix6 L = RelativePoseFactor::SqrtInformationOfCovariance(C);
  EXPECT_TRUE(testing::MatricesNear(L * C * L.transpose(), Matrix6::Identity(), 1e-9, 1e-9));
  EXPECT_TRUE(testing::MatricesNear(L.transpose() * L, Matrix6(C.inverse()), 1e-6, 1e-9));
}

}  // namespace
}  // namespace swarmlio
