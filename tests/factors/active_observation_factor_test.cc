// ActiveObservationFactor: the ego observes teammate j's body origin. Checks
// the prediction against its definition, the whitening against an
// independently built S, the analytic manifold Jacobians (random, near-identity
// and near-pi rotations) and that the check rejects flipped columns, and
// TangentJacobian against the stated formulas and numeric differentiation.
#include "factors/active_observation_factor.h"

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

// The definition, written independently of the factor.
Eigen::Vector3d ActivePrediction(const EgoState& ego,
                                 const GlobalExtrinsic& T,
                                 const Eigen::Vector3d& p_bj_in_Gj) {
  const Eigen::Vector3d p_bj_in_Gi = T.R_Ga_Gb() * p_bj_in_Gj + T.p_Gb_in_Ga;
  return ego.R_G_b().transpose() * (p_bj_in_Gi - ego.p_b_in_G);
}

// One randomly drawn observation problem: true states, the constants, and a
// factor whose S is linearized at slightly perturbed rotations.
struct Problem {
  EgoState ego;
  GlobalExtrinsic extrinsic;
  Eigen::Vector3d p_bj_in_Gj;
  Eigen::Vector3d z;
  Eigen::Matrix3d Sigma_obs, Sigma_p;
  Eigen::Matrix3d R_Gi_bi_lin, R_Gi_Gj_lin;

  Problem(Sampler* s, double ego_angle, double extrinsic_angle, bool exact_measurement)
      : ego(s->Ego(ego_angle)), extrinsic(s->Extrinsic(extrinsic_angle)) {
    p_bj_in_Gj = s->Gaussian3(8.0);
    z = ActivePrediction(ego, extrinsic, p_bj_in_Gj);
    if (!exact_measurement) z += s->Gaussian3(0.3);
    Sigma_obs = s->Covariance3(0.1, 1e-3);
    Sigma_p = s->Covariance3(0.1, 1e-3);
    R_Gi_bi_lin = ego.R_G_b() * so3::Exp(s->Gaussian3(0.02));
    R_Gi_Gj_lin = extrinsic.R_Ga_Gb() * so3::Exp(s->Gaussian3(0.02));
  }
  ActiveObservationFactor Factor() const {
    return ActiveObservationFactor(z, p_bj_in_Gj, Sigma_obs, Sigma_p, R_Gi_bi_lin, R_Gi_Gj_lin);
  }
  // S written out from its definition.
  Eigen::Matrix3d S() const {
    const Eigen::Matrix3d A = R_Gi_bi_lin.transpose() * R_Gi_Gj_lin;
    return Sigma_obs + A * Sigma_p * A.transpose();
  }
};

// Ceres parameter storage for the two blocks and their manifolds.
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

Eigen::Vector3d EvaluateResidual(const ceres::CostFunction& cost, const Blocks& b) {
  Eigen::Vector3d r;
  const std::vector<const double*> p = b.pointers();
  EXPECT_TRUE(cost.Evaluate(p.data(), r.data(), nullptr));
  return r;
}

TEST(ActiveObservationFactor, Sizes) {
  Sampler s(1);
  const Problem pr(&s, -1.0, -1.0, true);
  const ActiveObservationFactor factor = pr.Factor();
  EXPECT_EQ(factor.num_residuals(), 3);
  EXPECT_EQ(factor.parameter_block_sizes(), (std::vector<int32_t>{19, 7}));
}

TEST(ActiveObservationFactor, ResidualIsZeroAtTheTrueConfiguration) {
  Sampler s(2);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem pr(&s, -1.0, -1.0, /*exact_measurement=*/true);
    const ActiveObservationFactor factor = pr.Factor();
    EXPECT_NEAR((factor.Predict(pr.ego, pr.extrinsic) - pr.z).norm(), 0.0, 1e-12);
    const Blocks b(pr.ego, pr.extrinsic);
    EXPECT_NEAR(EvaluateResidual(factor, b).norm(), 0.0, 1e-9);
  }
}

TEST(ActiveObservationFactor, PredictionMatchesTheDefinition) {
  Sampler s(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem pr(&s, -1.0, -1.0, true);
    const EgoState other_ego = s.Ego(-1.0);
    const GlobalExtrinsic other_ext = s.Extrinsic(-1.0);
    EXPECT_NEAR((pr.Factor().Predict(other_ego, other_ext) -
                 ActivePrediction(other_ego, other_ext, pr.p_bj_in_Gj))
                    .norm(),
                0.0, 1e-10);
  }
}

TEST(ActiveObservationFactor, WhitenedResidualIsTheMahalanobisDistance) {
  Sampler s(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem pr(&s, -1.0, -1.0, /*exact_measurement=*/false);
    const ActiveObservationFactor factor = pr.Factor();
    const EgoState ego = s.Ego(-1.0);
    const GlobalExtrinsic ext = s.Extrinsic(-1.0);
    const Blocks b(ego, ext);
    const Eigen::Vector3d r = EvaluateResidual(factor, b);
    const Eigen::Vector3d e = ActivePrediction(ego, ext, pr.p_bj_in_Gj) - pr.z;
    const Eigen::Matrix3d S = pr.S();
    const double mahalanobis = e.dot(S.ldlt().solve(e));
    EXPECT_NEAR(r.squaredNorm(), mahalanobis, 1e-9 * mahalanobis);
    EXPECT_NEAR((factor.covariance() - S).norm(), 0.0, 1e-12 * S.norm());
    // U^-1 is lower triangular and whitens S: U^-1 S U^-T = I.
    const Eigen::Matrix3d& W = factor.sqrt_information();
    EXPECT_EQ(W(0, 1), 0.0);
    EXPECT_EQ(W(0, 2), 0.0);
    EXPECT_EQ(W(1, 2), 0.0);
    EXPECT_NEAR((W * S * W.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
  }
}

TEST(ActiveObservationFactor, JacobianIsCorrectAtRandomNearIdentityAndNearPiRotations) {
  Sampler s(5);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  for (double ego_angle : angles) {
    for (double ext_angle : angles) {
      SCOPED_TRACE(::testing::Message() << "ego " << ego_angle << ", extrinsic " << ext_angle);
      for (int trial = 0; trial < 4; ++trial) {
        const Problem pr(&s, ego_angle, ext_angle, trial % 2 == 0);
        const ActiveObservationFactor factor = pr.Factor();
        const Blocks b(pr.ego, pr.extrinsic);
        EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
      }
    }
  }
}

TEST(ActiveObservationFactor, FlippedColumnsAreRejected) {
  Sampler s(6);
  const Problem pr(&s, -1.0, -1.0, false);
  const ActiveObservationFactor factor = pr.Factor();
  const Blocks b(pr.ego, pr.extrinsic);
  ASSERT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
  const testing::FlippedJacobianColumns ego_rotation(&factor, /*block=*/0, /*num_columns=*/4);
  const testing::FlippedJacobianColumns ego_position(&factor, 0, 3, /*first_column=*/4);
  const testing::FlippedJacobianColumns ext_rotation(&factor, 1, 4);
  const testing::FlippedJacobianColumns ext_position(&factor, 1, 3, 4);
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_rotation, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_position, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ext_rotation, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ext_position, b.manifolds(), b.pointers()));
}

TEST(ActiveObservationFactor, TangentJacobianIsTheStatedFormula) {
  Sampler s(7);
  for (int trial = 0; trial < 10; ++trial) {
    const Problem pr(&s, -1.0, -1.0, false);
    const ActiveObservationFactor factor = pr.Factor();
    Eigen::Matrix<double, 3, 18> J_ego;
    Eigen::Matrix<double, 3, 6> J_ext;
    factor.TangentJacobian(pr.ego, pr.extrinsic, &J_ego, &J_ext);
    // Unwhiten with U = chol(S) and compare with the header's formulas.
    const Eigen::Matrix3d U = pr.S().llt().matrixL();
    const Eigen::Matrix3d Rt = pr.ego.R_G_b().transpose();
    const Eigen::Vector3d h = ActivePrediction(pr.ego, pr.extrinsic, pr.p_bj_in_Gj);
    Eigen::Matrix<double, 3, 18> H_ego = Eigen::Matrix<double, 3, 18>::Zero();
    H_ego.block<3, 3>(0, 0) = so3::Hat(h);
    H_ego.block<3, 3>(0, 3) = -Rt;
    Eigen::Matrix<double, 3, 6> H_ext;
    H_ext.leftCols<3>() = -Rt * pr.extrinsic.R_Ga_Gb() * so3::Hat(pr.p_bj_in_Gj);
    H_ext.rightCols<3>() = Rt;
    EXPECT_TRUE(testing::MatricesNear(U * J_ego, H_ego, 1e-10, 1e-12));
    EXPECT_TRUE(testing::MatricesNear(U * J_ext, H_ext, 1e-10, 1e-12));
  }
}

TEST(ActiveObservationFactor, TangentJacobianMatchesNumericDifferentiation) {
  Sampler s(8);
  const double angles[] = {-1.0, M_PI - 1e-3, 1e-9};
  for (double angle : angles) {
    SCOPED_TRACE(angle);
    for (int trial = 0; trial < 5; ++trial) {
      const Problem pr(&s, angle, angle, false);
      const ActiveObservationFactor factor = pr.Factor();
      Eigen::Matrix<double, 3, 18> J_ego;
      Eigen::Matrix<double, 3, 6> J_ext;
      factor.TangentJacobian(pr.ego, pr.extrinsic, &J_ego, &J_ext);
      Eigen::Matrix<double, 3, 24> J;
      J << J_ego, J_ext;
      const Eigen::MatrixXd numeric = testing::NumericJacobian(
          [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
            return factor.Residual(pr.ego.BoxPlus(dx.head<18>()),
                                   pr.extrinsic.BoxPlus(dx.tail<6>()));
          },
          24);
      EXPECT_TRUE(testing::MatricesNear(J, numeric, 1e-6, 1e-7));
    }
  }
}

TEST(ActiveObservationFactor, ResidualsWithoutJacobianMatchFullEvaluation) {
  Sampler s(9);
  const Problem pr(&s, -1.0, -1.0, false);
  const ActiveObservationFactor factor = pr.Factor();
  const Blocks b(pr.ego, pr.extrinsic);
  const std::vector<const double*> p = b.pointers();
  Eigen::Vector3d r1, r2, r3;
  std::array<double, 3 * 19> j_ego;
  std::array<double, 3 * 7> j_ext;
  double* none[] = {nullptr, nullptr};
  double* only_ext[] = {nullptr, j_ext.data()};
  double* both[] = {j_ego.data(), j_ext.data()};
  ASSERT_TRUE(factor.Evaluate(p.data(), r1.data(), none));
  ASSERT_TRUE(factor.Evaluate(p.data(), r2.data(), only_ext));
  ASSERT_TRUE(factor.Evaluate(p.data(), r3.data(), both));
  EXPECT_EQ(r1, r2);
  EXPECT_EQ(r1, r3);
}

}  // namespace
}  // namespace swarmlio
