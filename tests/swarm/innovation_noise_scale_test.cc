// The per-teammate observation noise scale (src/swarm/innovation_noise_scale.h):
// it settles where the observations' NIS averages 3, whichever way the
// default is wrong, and the NIS counts the state's uncertainty.
#include "src/swarm/innovation_noise_scale.h"

#include <gtest/gtest.h>

#include <random>

namespace swarmlio::swarm::internal {
namespace {

// Innovations drawn with covariance `true_variance` I against a model of
// covariance scale * I: the scale after `n` observations.
double SettledScale(double true_variance, double rate, int n) {
  SwarmOptions options;
  options.noise_adaptation_rate = rate;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, std::sqrt(true_variance));
  double scale = 1.0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d e(normal(rng), normal(rng), normal(rng));
    scale = UpdatedNoiseScale(scale, e.squaredNorm() / scale, options);
  }
  return scale;
}

TEST(InnovationNoiseScale, SettlesOnTheObservedScatterEitherWay) {
  EXPECT_NEAR(SettledScale(4.0, 0.02, 3000), 4.0, 0.8);   // a noisier airframe
  EXPECT_NEAR(SettledScale(0.6, 0.02, 3000), 0.6, 0.12);  // a quieter one
  EXPECT_DOUBLE_EQ(SettledScale(4.0, 0.0, 3000), 1.0);    // off
  // Never beyond its range.
  EXPECT_DOUBLE_EQ(SettledScale(100.0, 0.02, 3000), SwarmOptions().max_noise_scale);
  EXPECT_DOUBLE_EQ(SettledScale(0.01, 0.02, 3000), SwarmOptions().min_noise_scale);
}

// One observation of a teammate 4 m ahead with a block in the state: the NIS
// is e^T S^-1 e with S holding the observation's own noise (not the share's
// inflation) and the state's uncertainty through the Jacobian.
TEST(InnovationNoiseScale, NisCountsTheStateUncertaintyAndTheTrueNoise) {
  SwarmState x;
  x.AddTeammate(5, GlobalExtrinsic());
  const int dim = x.layout().Dim();
  const Eigen::Matrix3d R = 0.01 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d R_j = 0.0001 * Eigen::Matrix3d::Identity();
  const double share = 0.5;
  ActiveObservationFactor factor(Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(4, 0, 0), R / share, R_j,
                                 Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity());
  const Eigen::Vector3d e(0.1, -0.05, 0.02);
  const Eigen::MatrixXd P0 = Eigen::MatrixXd::Zero(dim, dim);
  const double nis0 = ActiveObservationNis(factor, x, P0, 5, e, R / share, R);
  EXPECT_NEAR(nis0, e.dot((R + R_j).inverse() * e), 1e-9);
  // Uncertainty in the own position (the error state's p block): S grows by it.
  Eigen::MatrixXd P = P0;
  P.block<3, 3>(3, 3) = 0.04 * Eigen::Matrix3d::Identity();
  const double nis = ActiveObservationNis(factor, x, P, 5, e, R / share, R);
  EXPECT_NEAR(nis, e.dot((R + R_j + 0.04 * Eigen::Matrix3d::Identity()).inverse() * e), 1e-9);
}

}  // namespace
}  // namespace swarmlio::swarm::internal
