#include "swarmlio/teammate/cv_filter.h"

#include "swarmlio/common/time.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <random>

namespace swarmlio::teammate {
namespace {

TEST(ConstantVelocityFilter, PredictionFollowsTheModel) {
  ConstantVelocityFilter filter;
  filter.Initialize(ToNanoseconds(1.0), Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0.5, -1, 0), 0.1, 1.0);
  EXPECT_TRUE(filter.PositionAt(ToNanoseconds(3.0)).isApprox(Eigen::Vector3d(2, 0, 3)));
  const double q = 2.0;
  const ConstantVelocityFilter::Matrix6d P0 = filter.P();
  filter.PredictTo(ToNanoseconds(1.5), q);
  EXPECT_EQ(filter.stamp_ns(), 1'500'000'000);
  EXPECT_TRUE(filter.p().isApprox(Eigen::Vector3d(1.25, 1.5, 3)));
  // P' = F P F^T + Q for one axis: [s_p + dt^2 s_v + q dt^3/3, dt s_v + q dt^2/2; ., s_v + q dt].
  const double dt = 0.5, sp = P0(0, 0), sv = P0(3, 3);
  EXPECT_NEAR(filter.P()(0, 0), sp + dt * dt * sv + q * q * dt * dt * dt / 3, 1e-12);
  EXPECT_NEAR(filter.P()(0, 3), dt * sv + q * q * dt * dt / 2, 1e-12);
  EXPECT_NEAR(filter.P()(3, 3), sv + q * q * dt, 1e-12);
  EXPECT_NEAR(filter.P()(0, 1), 0.0, 1e-15);
}

TEST(ConstantVelocityFilter, ConvergesToAConstantVelocityTarget) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.03);
  const Eigen::Vector3d p0(4, -1, 1), v(0.8, 0.3, -0.1);
  ConstantVelocityFilter filter;
  filter.Initialize(0, p0, Eigen::Vector3d::Zero(), 0.03, 1.0);
  const Eigen::Matrix3d R = 0.03 * 0.03 * Eigen::Matrix3d::Identity();
  for (int k = 1; k <= 100; ++k) {
    const double t = 0.1 * k;
    filter.PredictTo(ToNanoseconds(t), 0.05);
    const Eigen::Vector3d z = p0 + v * t + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const double nis = filter.Update(z, R);
    EXPECT_LT(nis, 30.0);
  }
  EXPECT_LT((filter.v() - v).norm(), 0.1);
  EXPECT_LT((filter.p() - (p0 + v * 10.0)).norm(), 0.05);
  // The update shrinks the position covariance below the measurement's.
  EXPECT_LT(filter.P()(0, 0), 0.03 * 0.03);
  // Symmetric and positive definite.
  EXPECT_TRUE(filter.P().isApprox(filter.P().transpose()));
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<ConstantVelocityFilter::Matrix6d>(filter.P()).eigenvalues().minCoeff(), 0.0);
}

TEST(ConstantVelocityFilter, PredictionWithAKnownVelocity) {
  ConstantVelocityFilter filter;
  filter.Initialize(0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.1, 1.0);
  filter.PredictWithVelocity(ToNanoseconds(2.0), Eigen::Vector3d(1, 0, 0), 0.1);
  EXPECT_TRUE(filter.p().isApprox(Eigen::Vector3d(2, 0, 0)));
  EXPECT_TRUE(filter.v().isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_NEAR(filter.P()(0, 0), 0.01 + 0.01 * 4.0, 1e-12);
}

}  // namespace
}  // namespace swarmlio::teammate
