#include "swarmlio/lio/imu_propagator.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "tests/test_utils/helix_trajectory.h"

namespace swarmlio::lio {
namespace {

using L = ErrorStateLayout;
using N = ImuNoiseLayout;
using swarmlio::testing::MatricesNear;
using swarmlio::testing::NumericJacobian;

constexpr double kGravity = 9.81;
constexpr int64_t kImuPeriodNs = 5'000'000;  // 200 Hz

using swarmlio::testing::Helix;


Eigen::Vector3d RandomVector(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return {n(rng), n(rng), n(rng)};
}

EgoState RandomEgo(std::mt19937& rng) {
  EgoState x;
  x.q_G_b = so3::ExpQuaternion(RandomVector(rng, 1.0));
  x.p_b_in_G = RandomVector(rng, 10.0);
  x.v_b_in_G = RandomVector(rng, 2.0);
  x.gyro_bias = RandomVector(rng, 0.05);
  x.accel_bias = RandomVector(rng, 0.2);
  x.g_in_G = RandomVector(rng, 0.5) + Eigen::Vector3d(0, 0, -kGravity);
  return x;
}

ImuInput RandomInput(std::mt19937& rng) {
  ImuInput u;
  u.angular_velocity_rad_s = RandomVector(rng, 2.0);
  u.specific_force_m_s2 = RandomVector(rng, 3.0) + Eigen::Vector3d(0, 0, kGravity);
  return u;
}

using Vec = Eigen::Matrix<double, L::kEgoDim, 1>;

Eigen::MatrixXd NumericF(const EgoState& x, const ImuInput& u, double dt) {
  const EgoState y0 = PropagateEgo(x, u, dt);
  return NumericJacobian(
      [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
        return PropagateEgo(x.BoxPlus(Vec(dx)), u, dt).BoxMinus(y0);
      },
      L::kEgoDim);
}

Eigen::MatrixXd NumericG(const EgoState& x, const ImuInput& u, double dt) {
  const EgoState y0 = PropagateEgo(x, u, dt);
  return NumericJacobian(
      [&](const Eigen::VectorXd& w) -> Eigen::VectorXd {
        return PropagateEgo(x, u, dt, ImuNoiseVector(w)).BoxMinus(y0);
      },
      N::kDim);
}

std::unique_ptr<ImuPropagator> MakePropagator(const ImuPropagatorOptions& options = {}) {
  std::unique_ptr<ImuPropagator> p;
  EXPECT_TRUE(ImuPropagator::Create(options, &p).ok());
  return p;
}

TEST(ImuPropagatorJacobians, FAndGMatchNumericDifferentiationOnTheManifold) {
  std::mt19937 rng(7);
  for (double dt : {0.005, 0.05, 0.3}) {
    for (int trial = 0; trial < 5; ++trial) {
      const EgoState x = RandomEgo(rng);
      const ImuInput u = RandomInput(rng);
      EgoMatrix F;
      EgoNoiseMatrix G;
      EgoProcessJacobians(x, u, dt, &F, &G);
      EXPECT_TRUE(MatricesNear(F, NumericF(x, u, dt), 1e-7, 1e-7)) << "dt " << dt;
      EXPECT_TRUE(MatricesNear(G, NumericG(x, u, dt), 1e-7, 1e-7)) << "dt " << dt;
    }
  }
}

TEST(ImuPropagatorJacobians, CheckRejectsAFlippedSign) {
  std::mt19937 rng(8);
  const EgoState x = RandomEgo(rng);
  const ImuInput u = RandomInput(rng);
  const double dt = 0.05;
  EgoMatrix F;
  EgoNoiseMatrix G;
  EgoProcessJacobians(x, u, dt, &F, &G);
  const Eigen::MatrixXd F_num = NumericF(x, u, dt);
  const Eigen::MatrixXd G_num = NumericG(x, u, dt);
  for (const auto& [r, c] :
       {std::pair{L::kVelocity, L::kRotation}, std::pair{L::kRotation, L::kGyroBias},
        std::pair{L::kPosition, L::kAccelBias}}) {
    EgoMatrix flipped = F;
    flipped.block<3, 3>(r.offset, c.offset) *= -1.0;
    EXPECT_FALSE(MatricesNear(flipped, F_num, 1e-7, 1e-7));
  }
  EgoNoiseMatrix G_flipped = G;
  G_flipped.block<3, 3>(L::kVelocity.offset, N::kGyro.offset) *= -1.0;
  EXPECT_FALSE(MatricesNear(G_flipped, G_num, 1e-7, 1e-7));
}

TEST(ImuPropagator, NoiseFreeHelixIsReproduced) {
  const Helix helix;
  auto prop = MakePropagator();
  SwarmState x0;
  x0.ego = helix.State(0.0);
  ASSERT_TRUE(
      prop->Reset(x0, 1e-6 * Eigen::MatrixXd::Identity(x0.Dim(), x0.Dim()), helix.Sample(0), 1.0)
          .ok());
  const int steps = 400;  // 2 s at 200 Hz
  for (int k = 1; k <= steps; ++k) ASSERT_TRUE(prop->AddImu(helix.Sample(k * kImuPeriodNs)).ok());
  const double t = ToSeconds(steps * kImuPeriodNs);
  ASSERT_EQ(prop->stamp_ns(), steps * kImuPeriodNs);
  const Vec e = prop->state().ego.BoxMinus(helix.State(t));
  const double pos_err = e.segment<3>(L::kPosition.offset).norm();
  const double rot_err = e.segment<3>(L::kRotation.offset).norm();
  const double vel_err = e.segment<3>(L::kVelocity.offset).norm();
  std::printf(
      "[ figures  ] helix 2 s @200 Hz: |dp| = %.3e m, |dtheta| = %.3e rad, |dv| = %.3e m/s "
      "(travelled %.2f m)\n",
      pos_err, rot_err, vel_err, 3.0 * t);
  EXPECT_LT(pos_err, 1e-4);
  EXPECT_LT(rot_err, 1e-5);
  EXPECT_LT(vel_err, 1e-4);
  EXPECT_EQ(static_cast<int>(prop->scan_poses().size()), steps + 1);
}

TEST(ImuPropagator, PropagatesToExactlyATimeBetweenSamples) {
  const Helix helix;
  auto prop = MakePropagator();
  SwarmState x0;
  x0.ego = helix.State(0.0);
  ASSERT_TRUE(prop->Reset(x0, Eigen::MatrixXd::Identity(18, 18) * 1e-6, helix.Sample(0), 1.0).ok());
  for (int k = 1; k <= 20; ++k) ASSERT_TRUE(prop->AddImu(helix.Sample(k * kImuPeriodNs)).ok());
  const EgoState at_sample = prop->state().ego;
  const int64_t end_ns = 20 * kImuPeriodNs + 3'217'000;
  ASSERT_TRUE(prop->PropagateTo(end_ns).ok());
  EXPECT_EQ(prop->stamp_ns(), end_ns);
  EXPECT_EQ(prop->scan_poses().back().stamp_ns, end_ns);
  // Zero-order hold of the last sample over the remainder.
  const EgoState expected =
      PropagateEgo(at_sample, ToImuInput(helix.Sample(20 * kImuPeriodNs), 1.0), 3.217e-3);
  EXPECT_LT(prop->state().ego.BoxMinus(expected).norm(), 1e-12);
  // The hold of the last sample is first order over the 3.2 ms remainder:
  // |dv| ~ |jerk| tau^2 / 2 ~ 5e-5 m/s on this helix.
  EXPECT_LT(prop->state().ego.BoxMinus(helix.State(ToSeconds(end_ns))).norm(), 1e-4);
  // Continuing from there with the next sample stays on the trajectory.
  ASSERT_TRUE(prop->AddImu(helix.Sample(21 * kImuPeriodNs)).ok());
  EXPECT_LT(prop->state().ego.BoxMinus(helix.State(ToSeconds(21 * kImuPeriodNs))).norm(), 1e-4);
  EXPECT_TRUE(prop->PropagateTo(21 * kImuPeriodNs).ok());  // same time: no-op
  EXPECT_EQ(prop->PropagateTo(20 * kImuPeriodNs).code(), Status::Code::kOutOfRange);
}

TEST(ImuPropagator, PropagateToWithTheNextSampleIsSecondOrder) {
  const Helix helix;
  auto prop = MakePropagator();
  SwarmState x0;
  x0.ego = helix.State(0.0);
  ASSERT_TRUE(prop->Reset(x0, Eigen::MatrixXd::Identity(18, 18) * 1e-6, helix.Sample(0), 1.0).ok());
  for (int k = 1; k <= 20; ++k) ASSERT_TRUE(prop->AddImu(helix.Sample(k * kImuPeriodNs)).ok());
  const int64_t end_ns = 20 * kImuPeriodNs + 3'217'000;
  const ImuSample next = helix.Sample(21 * kImuPeriodNs);
  ImuSample early = next;
  early.stamp_ns = end_ns - 1;
  EXPECT_EQ(prop->PropagateTo(end_ns, &early).code(), Status::Code::kInvalidArgument);
  ASSERT_TRUE(prop->PropagateTo(end_ns, &next).ok());
  EXPECT_EQ(prop->stamp_ns(), end_ns);
  const double err = prop->state().ego.BoxMinus(helix.State(ToSeconds(end_ns))).norm();
  std::printf("[ figures  ] propagate 3.217 ms past a sample: error %.2e with the next sample\n",
              err);
  EXPECT_LT(err, 1e-5);
  ASSERT_TRUE(prop->AddImu(next).ok());
  EXPECT_LT(prop->state().ego.BoxMinus(helix.State(ToSeconds(21 * kImuPeriodNs))).norm(), 1e-5);
}

TEST(ImuPropagator, SampleAtAReachedTargetBecomesTheInput) {
  const Helix helix;
  auto prop = MakePropagator();
  SwarmState x0;
  x0.ego = helix.State(0.0);
  ASSERT_TRUE(prop->Reset(x0, Eigen::MatrixXd::Identity(18, 18) * 1e-6, helix.Sample(0), 1.0).ok());
  const ImuSample s1 = helix.Sample(kImuPeriodNs);
  ASSERT_TRUE(prop->PropagateTo(kImuPeriodNs, &s1).ok());
  const EgoState at_target = prop->state().ego;
  ASSERT_TRUE(prop->AddImu(s1).ok());
  EXPECT_EQ(prop->num_skipped_out_of_order(), 0);
  EXPECT_EQ(prop->state().ego.BoxMinus(at_target).norm(), 0.0);
  EXPECT_EQ(prop->scan_poses().size(), 2u);
  EXPECT_EQ(prop->scan_poses().back().angular_velocity_in_b_rad_s, s1.angular_velocity_rad_s);
  ASSERT_TRUE(prop->AddImu(s1).ok());
  EXPECT_EQ(prop->num_skipped_duplicate(), 1);
}

TEST(ImuPropagator, SkipsDuplicateAndOutOfOrderSamples) {
  const Helix helix;
  SwarmState x0;
  x0.ego = helix.State(0.0);
  const Eigen::MatrixXd P0 = Eigen::MatrixXd::Identity(18, 18) * 1e-4;
  auto clean = MakePropagator();
  auto dirty = MakePropagator();
  ASSERT_TRUE(clean->Reset(x0, P0, helix.Sample(0), 1.0).ok());
  ASSERT_TRUE(dirty->Reset(x0, P0, helix.Sample(0), 1.0).ok());
  for (int k = 1; k <= 10; ++k) {
    ASSERT_TRUE(clean->AddImu(helix.Sample(k * kImuPeriodNs)).ok());
    ASSERT_TRUE(dirty->AddImu(helix.Sample(k * kImuPeriodNs)).ok());
    ImuSample duplicate = helix.Sample(k * kImuPeriodNs);
    duplicate.angular_velocity_rad_s *= 5.0;  // must be ignored
    ASSERT_TRUE(dirty->AddImu(duplicate).ok());
    if (k > 2) {
      ASSERT_TRUE(dirty->AddImu(helix.Sample((k - 2) * kImuPeriodNs)).ok());
    }
  }
  EXPECT_EQ(dirty->num_skipped_duplicate(), 10);
  EXPECT_EQ(dirty->num_skipped_out_of_order(), 8);
  EXPECT_EQ(dirty->state().ego.BoxMinus(clean->state().ego).norm(), 0.0);
  EXPECT_EQ((dirty->covariance() - clean->covariance()).norm(), 0.0);
}

TEST(ImuPropagator, RefusesGapsAndNonFiniteSamples) {
  const Helix helix;
  ImuPropagatorOptions options;
  options.max_gap_s = 0.05;
  auto prop = MakePropagator(options);
  SwarmState x0;
  x0.ego = helix.State(0.0);
  ASSERT_TRUE(prop->Reset(x0, Eigen::MatrixXd::Identity(18, 18), helix.Sample(0), 1.0).ok());
  const EgoState before = prop->state().ego;
  const Status gap = prop->AddImu(helix.Sample(60'000'000));
  EXPECT_EQ(gap.code(), Status::Code::kOutOfRange);
  EXPECT_NE(gap.message().find("max_gap_s"), std::string::npos) << gap.message();
  EXPECT_EQ(prop->num_gaps(), 1);
  EXPECT_EQ(prop->PropagateTo(70'000'000).code(), Status::Code::kOutOfRange);
  ImuSample bad = helix.Sample(kImuPeriodNs);
  bad.linear_acceleration.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(prop->AddImu(bad).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(prop->num_rejected_non_finite(), 1);
  EXPECT_EQ(prop->state().ego.BoxMinus(before).norm(), 0.0);
  EXPECT_EQ(prop->stamp_ns(), 0);
  EXPECT_TRUE(prop->AddImu(helix.Sample(kImuPeriodNs)).ok());
}

TEST(ImuPropagator, RejectsInvalidOptionsAndCovarianceSize) {
  ImuPropagatorOptions options;
  options.process_noise.gyro_cov_rad2_s2 = -1.0;
  std::unique_ptr<ImuPropagator> p;
  const Status s = ImuPropagator::Create(options, &p);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("process_noise.gyro_cov_rad2_s2"), std::string::npos) << s.message();
  auto prop = MakePropagator();
  SwarmState x0;
  x0.AddTeammate(3, GlobalExtrinsic());
  EXPECT_EQ(prop->Reset(x0, Eigen::MatrixXd::Identity(18, 18), ImuSample(), 1.0).code(),
            Status::Code::kInvalidArgument);
}

// One step of the class against the dense formula F P F^T + G Q G^T with the
// full (ego + teammates) F and G.
TEST(ImuPropagator, CovarianceWithTeammatesMatchesDenseFormula) {
  std::mt19937 rng(11);
  SwarmState x;
  x.ego = RandomEgo(rng);
  x.AddTeammate(4, GlobalExtrinsic());
  x.AddTeammate(9, GlobalExtrinsic());
  const int n = x.Dim();
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd P0 = A * A.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
  ImuSample s0, s1;
  s0.stamp_ns = 1'000'000'000;
  s0.angular_velocity_rad_s = RandomVector(rng, 1.0);
  s0.linear_acceleration = RandomVector(rng, 1.0) + Eigen::Vector3d(0, 0, kGravity);
  s1 = s0;
  s1.stamp_ns += kImuPeriodNs;
  s1.angular_velocity_rad_s += RandomVector(rng, 0.1);
  ImuPropagatorOptions options;
  auto prop = MakePropagator(options);
  ASSERT_TRUE(prop->Reset(x, P0, s0, 1.0).ok());
  ASSERT_TRUE(prop->AddImu(s1).ok());

  ImuInput mid = ToImuInput(s0, 1.0);
  mid.angular_velocity_rad_s = 0.5 * (s0.angular_velocity_rad_s + s1.angular_velocity_rad_s);
  const double dt = 0.005;
  EgoMatrix Fe;
  EgoNoiseMatrix Ge;
  EgoProcessJacobians(x.ego, mid, dt, &Fe, &Ge);
  const int nw = N::kDim + 6 * 2;
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
  F.topLeftCorner(18, 18) = Fe;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, nw);
  G.topLeftCorner(18, N::kDim) = Ge;
  Eigen::VectorXd q(nw);
  q.head(N::kDim) = EgoNoiseCovariance(options.process_noise).diagonal();
  int col = N::kDim;
  for (int id : {4, 9}) {
    const Segment rot = x.layout().TeammateRotation(id);
    const Segment tr = x.layout().TeammateTranslation(id);
    G.block(rot.offset, col, 3, 3) = dt * Eigen::Matrix3d::Identity();
    q.segment<3>(col).setConstant(options.process_noise.teammate_rotation_cov_rad2_s2);
    G.block(tr.offset, col + 3, 3, 3) = dt * Eigen::Matrix3d::Identity();
    q.segment<3>(col + 3).setConstant(options.process_noise.teammate_translation_cov_m2_s2);
    col += 6;
  }
  const Eigen::MatrixXd expected = F * P0 * F.transpose() + G * q.asDiagonal() * G.transpose();
  EXPECT_TRUE(MatricesNear(prop->covariance(), expected, 1e-12, 1e-12));
}

TEST(ImuPropagator, CovarianceStaysSymmetricPositiveDefinite) {
  const Helix helix;
  auto prop = MakePropagator();
  SwarmState x0;
  x0.ego = helix.State(0.0);
  x0.AddTeammate(2, GlobalExtrinsic());
  Eigen::MatrixXd P0 = Eigen::MatrixXd::Identity(x0.Dim(), x0.Dim()) * 1e-6;
  ASSERT_TRUE(prop->Reset(x0, P0, helix.Sample(0), 1.0).ok());
  for (int k = 1; k <= 2000; ++k) {  // 10 s
    ASSERT_TRUE(prop->AddImu(helix.Sample(k * kImuPeriodNs)).ok());
    if (k % 200 != 0) continue;
    const Eigen::MatrixXd& P = prop->covariance();
    ASSERT_EQ((P - P.transpose()).norm(), 0.0);
    const double min_eig =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff();
    ASSERT_GT(min_eig, 0.0) << "k = " << k;
  }
}

// Monte Carlo: truth propagated with sampled noise (held over each interval)
// from a sampled initial error; the empirical covariance of x_true (-) x_hat
// must match the propagated P (NEES and per-axis variances).
TEST(ImuPropagator, MonteCarloErrorMatchesCovariance) {
  const Helix helix;
  ImuPropagatorOptions options;  // FAST-LIO defaults
  auto prop = MakePropagator(options);
  SwarmState x0;
  x0.ego = helix.State(0.0);
  x0.ego.gyro_bias = Eigen::Vector3d(0.01, -0.02, 0.005);
  x0.ego.accel_bias = Eigen::Vector3d(0.05, 0.02, -0.03);
  Eigen::VectorXd p0_diag(18);
  p0_diag << 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4,  // rot, pos, vel
      1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4;         // bg, ba, g
  const Eigen::MatrixXd P0 = p0_diag.asDiagonal();
  auto sample = [&](int64_t k) {
    ImuSample s = helix.Sample(k * kImuPeriodNs);
    s.angular_velocity_rad_s += x0.ego.gyro_bias;
    s.linear_acceleration += x0.ego.accel_bias;
    return s;
  };
  const int steps = 200;  // 1 s
  ASSERT_TRUE(prop->Reset(x0, P0, sample(0), 1.0).ok());
  std::vector<ImuInput> inputs;
  for (int k = 1; k <= steps; ++k) {
    ImuInput mid;
    mid.angular_velocity_rad_s =
        0.5 * (sample(k - 1).angular_velocity_rad_s + sample(k).angular_velocity_rad_s);
    mid.specific_force_m_s2 =
        0.5 * (sample(k - 1).linear_acceleration + sample(k).linear_acceleration);
    inputs.push_back(mid);
    ASSERT_TRUE(prop->AddImu(sample(k)).ok());
  }
  const EgoState x_hat = prop->state().ego;
  const Eigen::MatrixXd P = prop->covariance();

  std::mt19937 rng(2024);
  std::normal_distribution<double> normal;
  const Eigen::MatrixXd L0 = P0.llt().matrixL();
  const Eigen::VectorXd q_std = EgoNoiseCovariance(options.process_noise).diagonal().cwiseSqrt();
  const int runs = 300;
  const double dt = ToSeconds(kImuPeriodNs);
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(18, 18);
  const Eigen::MatrixXd P_inv = P.inverse();
  double nees_sum = 0.0;
  for (int run = 0; run < runs; ++run) {
    Vec z;
    for (int i = 0; i < 18; ++i) z[i] = normal(rng);
    EgoState x = x0.ego.BoxPlus(Vec(L0 * z));
    for (int k = 0; k < steps; ++k) {
      ImuNoiseVector w;
      for (int i = 0; i < N::kDim; ++i) w[i] = q_std[i] * normal(rng);
      x = PropagateEgo(x, inputs[k], dt, w);
    }
    const Vec e = x.BoxMinus(x_hat);
    S += e * e.transpose();
    nees_sum += e.dot(P_inv * e);
  }
  S /= runs;
  const double nees = nees_sum / runs;
  const double nees_sigma = std::sqrt(2.0 * 18 / runs);
  const double ratio_tolerance = 4.0 * std::sqrt(2.0 / runs);
  double min_ratio = 1e9, max_ratio = 0.0;
  for (int i = 0; i < 18; ++i) {
    const double ratio = S(i, i) / P(i, i);
    min_ratio = std::min(min_ratio, ratio);
    max_ratio = std::max(max_ratio, ratio);
    EXPECT_NEAR(ratio, 1.0, ratio_tolerance) << "error-state index " << i;
  }
  std::printf(
      "[ figures  ] MC %d runs, 1 s: mean NEES %.2f (expected 18 +- %.2f), "
      "var ratio empirical/P in [%.3f, %.3f] (tolerance +-%.3f); sigma_theta %.4f rad, "
      "sigma_p %.4f m\n",
      runs, nees, nees_sigma, min_ratio, max_ratio, ratio_tolerance, std::sqrt(P(0, 0)),
      std::sqrt(P(L::kPosition.offset, L::kPosition.offset)));
  EXPECT_NEAR(nees, 18.0, 4.0 * nees_sigma);
}

}  // namespace
}  // namespace swarmlio::lio
