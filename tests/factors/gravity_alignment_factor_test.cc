// GravityAlignmentFactor: R_Gi_Gj g_in_Gj = g_in_Gi. Checks the prediction
// against its definition, the whitening, the analytic manifold Jacobians
// (random, near-identity and near-pi rotations), that flipped columns are
// rejected, and that the residual ignores the extrinsic's translation and
// every ego column but gravity.
#include "factors/gravity_alignment_factor.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "test_utils/state_sampler.h"

namespace swarmlio {
namespace {

using Sampler = swarmlio::testing::StateSampler;

struct Problem {
  EgoState ego;
  GlobalExtrinsic extrinsic;
  Eigen::Vector3d g_in_Gj;
  Eigen::Matrix3d Sigma_g;
  double floor = 0.02;
  Eigen::Matrix3d R_lin;

  Problem(Sampler* s, double ego_angle, double ext_angle, bool exact)
      : ego(s->Ego(ego_angle)), extrinsic(s->Extrinsic(ext_angle)) {
    g_in_Gj = extrinsic.R_Ga_Gb().transpose() * ego.g_in_G;
    if (!exact) g_in_Gj += s->Gaussian3(0.05);
    Sigma_g = s->Covariance3(0.01, 1e-5);
    R_lin = extrinsic.R_Ga_Gb() * so3::Exp(s->Gaussian3(0.02));
  }
  GravityAlignmentFactor Factor() const {
    return GravityAlignmentFactor(g_in_Gj, Sigma_g, floor, R_lin);
  }
  Eigen::Matrix3d S() const {
    return R_lin * Sigma_g * R_lin.transpose() + floor * floor * Eigen::Matrix3d::Identity();
  }
};

struct Blocks {
  Blocks(const EgoState& ego, const GlobalExtrinsic& extrinsic) {
    ego.ToParameters(x_ego.data());
    extrinsic.ToParameters(x_ext.data());
  }
  std::vector<const double*> pointers() const { return {x_ego.data(), x_ext.data()}; }
  std::vector<const ceres::Manifold*> manifolds() const {
    return {&ego_manifold, &extrinsic_manifold};
  }
  std::array<double, EgoState::kAmbientSize> x_ego;
  std::array<double, GlobalExtrinsic::kAmbientSize> x_ext;
  EgoStateManifold ego_manifold;
  GlobalExtrinsicManifold extrinsic_manifold;
};

TEST(GravityAlignmentFactor, ZeroAtConsistentGravityAndTheMahalanobisDistanceElsewhere) {
  Sampler s(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem exact(&s, -1.0, -1.0, true);
    EXPECT_NEAR(exact.Factor().Residual(exact.ego, exact.extrinsic).norm(), 0.0, 1e-9);
    const Problem pr(&s, -1.0, -1.0, false);
    const GravityAlignmentFactor factor = pr.Factor();
    const EgoState ego = s.Ego(-1.0);
    const GlobalExtrinsic ext = s.Extrinsic(-1.0);
    const Eigen::Vector3d e = ext.R_Ga_Gb() * pr.g_in_Gj - ego.g_in_G;
    const double m2 = e.dot(pr.S().ldlt().solve(e));
    const Blocks b(ego, ext);
    Eigen::Vector3d r;
    const std::vector<const double*> p = b.pointers();
    ASSERT_TRUE(factor.Evaluate(p.data(), r.data(), nullptr));
    EXPECT_NEAR(r.squaredNorm(), m2, 1e-9 * m2);
    EXPECT_TRUE(testing::MatricesNear(factor.covariance(), pr.S(), 1e-12, 1e-14));
  }
}

TEST(GravityAlignmentFactor, JacobianIsCorrectAtRandomNearIdentityAndNearPiRotations) {
  Sampler s(2);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  for (double ego_angle : angles) {
    for (double ext_angle : angles) {
      SCOPED_TRACE(::testing::Message() << "ego " << ego_angle << ", extrinsic " << ext_angle);
      for (int trial = 0; trial < 3; ++trial) {
        const Problem pr(&s, ego_angle, ext_angle, trial % 2 == 0);
        const GravityAlignmentFactor factor = pr.Factor();
        const Blocks b(pr.ego, pr.extrinsic);
        EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
      }
    }
  }
}

TEST(GravityAlignmentFactor, FlippedColumnsAreRejected) {
  Sampler s(3);
  const Problem pr(&s, -1.0, -1.0, false);
  const GravityAlignmentFactor factor = pr.Factor();
  const Blocks b(pr.ego, pr.extrinsic);
  ASSERT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
  // Ambient ego columns: q 0-3, p 4-6, v 7-9, b_g 10-12, b_a 13-15, g 16-18.
  const testing::FlippedJacobianColumns ego_gravity(&factor, /*block=*/0, /*num_columns=*/3,
                                                    /*first_column=*/16);
  const testing::FlippedJacobianColumns ext_rotation(&factor, 1, 4);
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_gravity, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ext_rotation, b.manifolds(), b.pointers()));
}

TEST(GravityAlignmentFactor, TangentJacobianIsTheStatedFormulaAndNumeric) {
  Sampler s(4);
  for (int trial = 0; trial < 10; ++trial) {
    const Problem pr(&s, -1.0, -1.0, false);
    const GravityAlignmentFactor factor = pr.Factor();
    Eigen::Matrix<double, 3, 18> J_ego;
    Eigen::Matrix<double, 3, 6> J_ext;
    factor.TangentJacobian(pr.ego, pr.extrinsic, &J_ego, &J_ext);
    const Eigen::Matrix3d U = pr.S().llt().matrixL();
    Eigen::Matrix<double, 3, 18> H_ego = Eigen::Matrix<double, 3, 18>::Zero();
    H_ego.block<3, 3>(0, 15) = -Eigen::Matrix3d::Identity();
    Eigen::Matrix<double, 3, 6> H_ext = Eigen::Matrix<double, 3, 6>::Zero();
    H_ext.leftCols<3>() = -pr.extrinsic.R_Ga_Gb() * so3::Hat(pr.g_in_Gj);
    EXPECT_TRUE(testing::MatricesNear(U * J_ego, H_ego, 1e-10, 1e-12));
    EXPECT_TRUE(testing::MatricesNear(U * J_ext, H_ext, 1e-10, 1e-12));
    Eigen::Matrix<double, 3, 24> J;
    J << J_ego, J_ext;
    const Eigen::MatrixXd numeric = testing::NumericJacobian(
        [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
          return factor.Residual(pr.ego.BoxPlus(dx.head<18>()), pr.extrinsic.BoxPlus(dx.tail<6>()));
        },
        24);
    EXPECT_TRUE(testing::MatricesNear(J, numeric, 1e-6, 1e-7));
  }
}

}  // namespace
}  // namespace swarmlio
