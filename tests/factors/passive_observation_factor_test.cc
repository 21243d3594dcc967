// PassiveObservationFactor: a teammate observed the ego at t_j = t_k + dt.
// Checks the prediction against its definition (with and without time
// compensation, with the IMU retrodiction A(R, b_a, g)), the whitening against an independently built S, the
// analytic manifold Jacobians (random, near-identity and near-pi rotations,
// nonzero dt) and that the check rejects flipped columns, and TangentJacobian
// against the stated formulas and numeric differentiation.
#include "factors/passive_observation_factor.h"

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

// The IMU part of the ego's motion back to t_j, written from its definition:
// A = R (u + M (b_a0 - b_a)) + W g with u, M formed at the linearization
// state `lin` (R0, b_a0, g0).
Eigen::Vector3d RetrodictedA(const EgoState& ego, const ImuRetrodiction& r, const EgoState& lin) {
  const Eigen::Matrix3d R0_T = lin.R_G_b().transpose();
  const Eigen::Vector3d u = R0_T * (r.weighted_acc_in_G - r.weight_s2 * lin.g_in_G);
  const Eigen::Matrix3d M = R0_T * r.weighted_R_G_b;
  return ego.R_G_b() * (u + M * (lin.accel_bias - ego.accel_bias)) + r.weight_s2 * ego.g_in_G;
}

// The definition, written independently of the factor.
Eigen::Vector3d PassivePrediction(const EgoState& ego,
                                  const GlobalExtrinsic& T,
                                  double dt,
                                  const Eigen::Matrix3d& R_Gj_bj,
                                  const Eigen::Vector3d& p_bj_in_Gj,
                                  const ImuRetrodiction& r = ImuRetrodiction(),
                                  const EgoState& lin = EgoState()) {
  const Eigen::Vector3d p_bi_in_Gi_at_tj =
      ego.p_b_in_G + ego.v_b_in_G * dt + RetrodictedA(ego, r, lin);
  const Eigen::Vector3d p_bi_in_Gj = T.R_Ga_Gb().transpose() * (p_bi_in_Gi_at_tj - T.p_Gb_in_Ga);
  return R_Gj_bj.transpose() * (p_bi_in_Gj - p_bj_in_Gj);
}

// One randomly drawn observation problem: true states, the teammate's pose at
// t_j, and a factor whose S is linearized at a slightly perturbed state.
struct Problem {
  EgoState ego;
  GlobalExtrinsic extrinsic;
  double dt;
  ImuRetrodiction r;  // the IMU part of the motion back to t_j (W = dt^2 / 2)
  Eigen::Matrix3d R_Gj_bj;
  Eigen::Vector3d p_bj_in_Gj;
  Eigen::Vector3d z;
  Eigen::Matrix3d Sigma_obs, Sigma_theta, Sigma_p;
  EgoState ego_lin;
  GlobalExtrinsic extrinsic_lin;

  Problem(Sampler* s,
          double ego_angle,
          double extrinsic_angle,
          double teammate_angle,
          double dt_s,
          bool exact_measurement)
      : ego(s->Ego(ego_angle)), extrinsic(s->Extrinsic(extrinsic_angle)), dt(dt_s) {
    ego_lin = ego.BoxPlus(s->Gaussian(18, 0.02));
    extrinsic_lin = extrinsic.BoxPlus(s->Gaussian(6, 0.02));
    // A plausible history: W = dt^2 / 2, the attitude over it near the
    // current one, a few m/s^2 of acceleration.
    r.weight_s2 = 0.5 * dt * dt;
    r.weighted_acc_in_G = r.weight_s2 * s->Gaussian3(3.0);
    r.weighted_R_G_b = r.weight_s2 * (ego.R_G_b() * so3::Exp(s->Gaussian3(0.05)));
    R_Gj_bj = s->Rotation(teammate_angle).toRotationMatrix();
    p_bj_in_Gj = s->Gaussian3(8.0);
    z = PassivePrediction(ego, extrinsic, dt, R_Gj_bj, p_bj_in_Gj, r, ego_lin);
    if (!exact_measurement) z += s->Gaussian3(0.3);
    Sigma_obs = s->Covariance3(0.1, 1e-3);
    Sigma_theta = s->Covariance3(0.01, 1e-6);
    Sigma_p = s->Covariance3(0.1, 1e-3);
  }
  PassiveObservationFactor Factor() const {
    return PassiveObservationFactor(z, dt, R_Gj_bj, p_bj_in_Gj, Sigma_obs, Sigma_theta, Sigma_p,
                                    ego_lin, extrinsic_lin, r);
  }
  // S written out from its definition, at h0 = h(ego_lin, extrinsic_lin).
  Eigen::Matrix3d S() const {
    const Eigen::Matrix3d H =
        so3::Hat(PassivePrediction(ego_lin, extrinsic_lin, dt, R_Gj_bj, p_bj_in_Gj, r, ego_lin));
    return Sigma_obs + H * Sigma_theta * H.transpose() + R_Gj_bj.transpose() * Sigma_p * R_Gj_bj;
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

TEST(PassiveObservationFactor, Sizes) {
  Sampler s(1);
  const Problem pr(&s, -1.0, -1.0, -1.0, 0.05, true);
  const PassiveObservationFactor factor = pr.Factor();
  EXPECT_EQ(factor.num_residuals(), 3);
  EXPECT_EQ(factor.parameter_block_sizes(), (std::vector<int32_t>{19, 7}));
  EXPECT_EQ(factor.dt(), 0.05);
}

TEST(PassiveObservationFactor, ResidualIsZeroAtTheTrueConfiguration) {
  Sampler s(2);
  for (double dt : {0.0, 0.07, -0.04}) {
    for (int trial = 0; trial < 10; ++trial) {
      const Problem pr(&s, -1.0, -1.0, -1.0, dt, /*exact_measurement=*/true);
      const PassiveObservationFactor factor = pr.Factor();
      EXPECT_NEAR((factor.Predict(pr.ego, pr.extrinsic) - pr.z).norm(), 0.0, 1e-12);
      const Blocks b(pr.ego, pr.extrinsic);
      EXPECT_NEAR(EvaluateResidual(factor, b).norm(), 0.0, 1e-9);
    }
  }
}

TEST(PassiveObservationFactor, TimeCompensationMovesTheEgoByItsVelocity) {
  Sampler s(3);
  const Problem pr(&s, -1.0, -1.0, -1.0, 0.08, true);
  const PassiveObservationFactor factor = pr.Factor();
  // With dt (and the retrodiction A), the prediction equals the dt = 0, A = 0
  // prediction of the ego moved by v dt + A.
  EgoState moved = pr.ego;
  moved.p_b_in_G += pr.ego.v_b_in_G * 0.08 + RetrodictedA(pr.ego, pr.r, pr.ego_lin);
  const PassiveObservationFactor no_compensation(pr.z, 0.0, pr.R_Gj_bj, pr.p_bj_in_Gj, pr.Sigma_obs,
                                                 pr.Sigma_theta, pr.Sigma_p, pr.ego_lin,
                                                 pr.extrinsic_lin);
  EXPECT_NEAR(
      (factor.Predict(pr.ego, pr.extrinsic) - no_compensation.Predict(moved, pr.extrinsic)).norm(),
      0.0, 1e-12);
  // dt = 0, no history: velocity, attitude, accelerometer bias and gravity
  // do not enter (zero columns).
  EgoState other = pr.ego;
  other.v_b_in_G = s.Gaussian3(3.0);
  other.q_G_b = s.Rotation(-1.0);
  other.accel_bias = s.Gaussian3(0.5);
  other.g_in_G = s.Gaussian3(9.0);
  EXPECT_EQ(no_compensation.Predict(pr.ego, pr.extrinsic),
            no_compensation.Predict(other, pr.extrinsic));
  Eigen::Matrix<double, 3, 18> J_ego;
  no_compensation.TangentJacobian(pr.ego, pr.extrinsic, &J_ego, nullptr);
  EXPECT_EQ(J_ego.middleCols<3>(ErrorStateLayout::kVelocity.offset).norm(), 0.0);
  EXPECT_EQ(J_ego.middleCols<3>(ErrorStateLayout::kRotation.offset).norm(), 0.0);
  EXPECT_EQ(J_ego.middleCols<3>(ErrorStateLayout::kAccelBias.offset).norm(), 0.0);
  EXPECT_EQ(J_ego.middleCols<3>(ErrorStateLayout::kGravity.offset).norm(), 0.0);
}

TEST(PassiveObservationFactor, PredictionMatchesTheDefinition) {
  Sampler s(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem pr(&s, -1.0, -1.0, -1.0, 0.03, true);
    const EgoState other_ego = s.Ego(-1.0);
    const GlobalExtrinsic other_ext = s.Extrinsic(-1.0);
    EXPECT_NEAR((pr.Factor().Predict(other_ego, other_ext) -
                 PassivePrediction(other_ego, other_ext, pr.dt, pr.R_Gj_bj, pr.p_bj_in_Gj, pr.r, pr.ego_lin))
                    .norm(),
                0.0, 1e-10);
  }
}

TEST(PassiveObservationFactor, WhitenedResidualIsTheMahalanobisDistance) {
  Sampler s(5);
  for (int trial = 0; trial < 20; ++trial) {
    const Problem pr(&s, -1.0, -1.0, -1.0, 0.05, /*exact_measurement=*/false);
    const PassiveObservationFactor factor = pr.Factor();
    const EgoState ego = s.Ego(-1.0);
    const GlobalExtrinsic ext = s.Extrinsic(-1.0);
    const Blocks b(ego, ext);
    const Eigen::Vector3d r = EvaluateResidual(factor, b);
    const Eigen::Vector3d e = PassivePrediction(ego, ext, pr.dt, pr.R_Gj_bj, pr.p_bj_in_Gj, pr.r, pr.ego_lin) - pr.z;
    const Eigen::Matrix3d S = pr.S();
    const double mahalanobis = e.dot(S.ldlt().solve(e));
    EXPECT_NEAR(r.squaredNorm(), mahalanobis, 1e-9 * mahalanobis);
    EXPECT_NEAR((factor.covariance() - S).norm(), 0.0, 1e-12 * S.norm());
    const Eigen::Matrix3d& W = factor.sqrt_information();
    EXPECT_EQ(W(0, 1), 0.0);
    EXPECT_EQ(W(0, 2), 0.0);
    EXPECT_EQ(W(1, 2), 0.0);
    EXPECT_NEAR((W * S * W.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
  }
}

TEST(PassiveObservationFactor, JacobianIsCorrectAtRandomNearIdentityAndNearPiRotations) {
  Sampler s(6);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  for (double ego_angle : angles) {
    for (double ext_angle : angles) {
      SCOPED_TRACE(::testing::Message() << "ego " << ego_angle << ", extrinsic " << ext_angle);
      for (int trial = 0; trial < 4; ++trial) {
        const double dt = trial == 3 ? 0.0 : s.Uniform(-0.1, 0.1);
        const Problem pr(&s, ego_angle, ext_angle, angles[trial], dt, trial % 2 == 0);
        const PassiveObservationFactor factor = pr.Factor();
        const Blocks b(pr.ego, pr.extrinsic);
        EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
      }
    }
  }
}

TEST(PassiveObservationFactor, FlippedColumnsAreRejected) {
  Sampler s(7);
  const Problem pr(&s, -1.0, -1.0, -1.0, 0.06, false);
  const PassiveObservationFactor factor = pr.Factor();
  const Blocks b(pr.ego, pr.extrinsic);
  ASSERT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, b.manifolds(), b.pointers()));
  // The gyro bias does not enter h: its columns are zero, so flipping them
  // changes nothing; attitude (through the retrodiction), position,
  // velocity, accelerometer bias, gravity and both extrinsic parts must be
  // rejected.
  std::array<double, 3 * 19> j_ego;
  std::array<double, 3 * 7> j_ext;
  Eigen::Vector3d r;
  double* jacobians[] = {j_ego.data(), j_ext.data()};
  const std::vector<const double*> p = b.pointers();
  ASSERT_TRUE(factor.Evaluate(p.data(), r.data(), jacobians));
  for (int row = 0; row < 3; ++row) {
    for (int col = 10; col < 13; ++col) EXPECT_EQ(j_ego[row * 19 + col], 0.0);
  }
  const testing::FlippedJacobianColumns ego_attitude(&factor, /*block=*/0, /*num_columns=*/4);
  const testing::FlippedJacobianColumns ego_accel_bias(&factor, 0, 3, 13);
  const testing::FlippedJacobianColumns ego_gravity(&factor, 0, 3, 16);
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_attitude, b.manifolds(), b.pointers()));
  EXPECT_FALSE(
      testing::CostFunctionJacobiansAreCorrect(ego_accel_bias, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_gravity, b.manifolds(), b.pointers()));
  const testing::FlippedJacobianColumns ego_position(&factor, /*block=*/0, /*num_columns=*/3,
                                                     /*first_column=*/4);
  const testing::FlippedJacobianColumns ego_velocity(&factor, 0, 3, 7);
  const testing::FlippedJacobianColumns ext_rotation(&factor, 1, 4);
  const testing::FlippedJacobianColumns ext_position(&factor, 1, 3, 4);
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_position, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ego_velocity, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ext_rotation, b.manifolds(), b.pointers()));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(ext_position, b.manifolds(), b.pointers()));
}

TEST(PassiveObservationFactor, TangentJacobianIsTheStatedFormula) {
  Sampler s(8);
  for (int trial = 0; trial < 10; ++trial) {
    const Problem pr(&s, -1.0, -1.0, -1.0, 0.05, false);
    const PassiveObservationFactor factor = pr.Factor();
    Eigen::Matrix<double, 3, 18> J_ego;
    Eigen::Matrix<double, 3, 6> J_ext;
    factor.TangentJacobian(pr.ego, pr.extrinsic, &J_ego, &J_ext);
    const Eigen::Matrix3d U = pr.S().llt().matrixL();
    const Eigen::Matrix3d R_e = pr.extrinsic.R_Ga_Gb();
    const Eigen::Matrix3d M = pr.R_Gj_bj.transpose() * R_e.transpose();
    const Eigen::Vector3d w =
        R_e.transpose() * (pr.ego.p_b_in_G + pr.ego.v_b_in_G * pr.dt +
                           RetrodictedA(pr.ego, pr.r, pr.ego_lin) - pr.extrinsic.p_Gb_in_Ga);
    // c = u + M_r (b_a0 - b_a), with u and M_r formed at ego_lin.
    const Eigen::Matrix3d R0_T = pr.ego_lin.R_G_b().transpose();
    const Eigen::Matrix3d M_r = R0_T * pr.r.weighted_R_G_b;
    const Eigen::Vector3d c =
        R0_T * (pr.r.weighted_acc_in_G - pr.r.weight_s2 * pr.ego_lin.g_in_G) +
        M_r * (pr.ego_lin.accel_bias - pr.ego.accel_bias);
    const Eigen::Matrix3d R = pr.ego.R_G_b();
    Eigen::Matrix<double, 3, 18> H_ego = Eigen::Matrix<double, 3, 18>::Zero();
    H_ego.block<3, 3>(0, 0) = -M * R * so3::Hat(c);
    H_ego.block<3, 3>(0, 3) = M;
    H_ego.block<3, 3>(0, 6) = M * pr.dt;
    H_ego.block<3, 3>(0, 12) = -M * R * M_r;
    H_ego.block<3, 3>(0, 15) = M * pr.r.weight_s2;
    Eigen::Matrix<double, 3, 6> H_ext;
    H_ext.leftCols<3>() = pr.R_Gj_bj.transpose() * so3::Hat(w);
    H_ext.rightCols<3>() = -M;
    EXPECT_TRUE(testing::MatricesNear(U * J_ego, H_ego, 1e-10, 1e-12));
    EXPECT_TRUE(testing::MatricesNear(U * J_ext, H_ext, 1e-10, 1e-12));
  }
}

TEST(PassiveObservationFactor, TangentJacobianMatchesNumericDifferentiation) {
  Sampler s(9);
  const double angles[] = {-1.0, M_PI - 1e-3, 1e-9};
  for (double angle : angles) {
    SCOPED_TRACE(angle);
    for (int trial = 0; trial < 5; ++trial) {
      const Problem pr(&s, angle, angle, angle, s.Uniform(-0.1, 0.1), false);
      const PassiveObservationFactor factor = pr.Factor();
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

TEST(PassiveObservationFactor, ResidualsWithoutJacobianMatchFullEvaluation) {
  Sampler s(10);
  const Problem pr(&s, -1.0, -1.0, -1.0, 0.05, false);
  const PassiveObservationFactor factor = pr.Factor();
  const Blocks b(pr.ego, pr.extrinsic);
  const std::vector<const double*> p = b.pointers();
  Eigen::Vector3d r1, r2, r3;
  std::array<double, 3 * 19> j_ego;
  std::array<double, 3 * 7> j_ext;
  double* none[] = {nullptr, nullptr};
  double* only_ego[] = {j_ego.data(), nullptr};
  double* both[] = {j_ego.data(), j_ext.data()};
  ASSERT_TRUE(factor.Evaluate(p.data(), r1.data(), none));
  ASSERT_TRUE(factor.Evaluate(p.data(), r2.data(), only_ego));
  ASSERT_TRUE(factor.Evaluate(p.data(), r3.data(), both));
  EXPECT_EQ(r1, r2);
  EXPECT_EQ(r1, r3);
}

}  // namespace
}  // namespace swarmlio
