#include "swarmlio/teammate/trajectory_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "swarmlio/common/time.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::teammate {
namespace {

// A smooth excited flight of teammate j in G_j.
Eigen::Vector3d TeammatePosition(double t) {
  return Eigen::Vector3d(2 + std::sin(0.7 * t) + 0.3 * std::cos(1.9 * t),
                         -1 + std::cos(0.5 * t) + 0.2 * std::sin(2.3 * t), 1.2 + 0.2 * std::sin(1.1 * t));
}
Eigen::Vector3d TeammateVelocity(double t) {
  return Eigen::Vector3d(0.7 * std::cos(0.7 * t) - 0.57 * std::sin(1.9 * t),
                         -0.5 * std::sin(0.5 * t) + 0.46 * std::cos(2.3 * t), 0.22 * std::cos(1.1 * t));
}

struct Scenario {
  Eigen::Matrix3d R_Gi_Gj;
  Eigen::Vector3d p_Gj_in_Gi;
  OdometryHistory teammate;
  TrajectoryBuffer tracker{300};
};

// Teammate broadcasts at 10 Hz with `drop` of them lost; the tracker sees it
// at 10 Hz, 0.043 s out of phase, with `noise_m` noise and a fraction
// `outliers` of its positions 0.8 m off.
Scenario Make(double drop, double noise_m, double outliers, uint64_t seed) {
  Scenario s;
  s.R_Gi_Gj = so3::Exp(Eigen::Vector3d(0.05, -0.03, 2.1));
  s.p_Gj_in_Gi = Eigen::Vector3d(4.0, -2.5, 0.3);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, noise_m);
  for (int k = 0; k <= 250; ++k) {
    const double t = 100.0 + 0.1 * k;
    if (u(rng) < drop) continue;
    TeammateOdometry m;
    m.stamp_ns = ToNanoseconds(t);
    m.drone_id = 3;
    m.p_bj_in_Gj = TeammatePosition(t - 100.0);
    m.v_bj_in_Gj = TeammateVelocity(t - 100.0);
    s.teammate.Add(m, 60.0);
  }
  for (int k = 0; k < 240; ++k) {
    const double t = 100.043 + 0.1 * k;
    Eigen::Vector3d p = s.R_Gi_Gj * TeammatePosition(t - 100.0) + s.p_Gj_in_Gi;
    p += Eigen::Vector3d(n(rng), n(rng), n(rng));
    if (u(rng) < outliers) p += Eigen::Vector3d(0.8, -0.5, 0.2);
    s.tracker.Push(ToNanoseconds(t), p);
  }
  return s;
}

double AngleDeg(const Eigen::Matrix3d& R) { return so3::Log(R).norm() * 180.0 / M_PI; }

TEST(MatchTrajectory, RecoversTheTransformExactlyWithoutNoise) {
  const Scenario s = Make(0.0, 0.0, 0.0, 1);
  MatchingOptions options;
  TrajectoryMatch match;
  ASSERT_TRUE(MatchTrajectory(s.tracker, s.teammate, options, &match).ok());
  EXPECT_EQ(match.num_pairs, 240);
  // The only error is the cubic interpolation between messages (mm).
  EXPECT_LT(match.mean_residual_m, 2e-3);
  EXPECT_LT(AngleDeg(s.R_Gi_Gj.transpose() * match.R_Gi_Gj), 0.05);
  EXPECT_LT((match.p_Gj_in_Gi - s.p_Gj_in_Gi).norm(), 2e-3);
}

TEST(MatchTrajectory, ToleratesLostMessagesAndOutliers) {
  // 30 % of the broadcasts lost, 2 cm noise, 5 % outliers 1 m off.
  const Scenario s = Make(0.3, 0.02, 0.05, 2);
  MatchingOptions options;
  TrajectoryMatch match;
  ASSERT_TRUE(MatchTrajectory(s.tracker, s.teammate, options, &match).ok());
  EXPECT_GT(match.num_pairs, 200);  // gaps up to max_gap_s are interpolated
  EXPECT_LT(match.num_inliers, match.num_pairs);
  EXPECT_GT(match.num_inliers, 0.9 * match.num_pairs);
  EXPECT_GT(match.mean_residual_m, 0.05);  // the outliers weigh on the decision residual
  EXPECT_LT(match.inlier_mean_residual_m, 0.05);
  EXPECT_LT(AngleDeg(s.R_Gi_Gj.transpose() * match.R_Gi_Gj), 0.5);
  EXPECT_LT((match.p_Gj_in_Gi - s.p_Gj_in_Gi).norm(), 0.03);
}

TEST(MatchTrajectory, LongGapsRemovePairs) {
  Scenario s = Make(0.0, 0.0, 0.0, 3);
  OdometryHistory gappy;
  for (const TeammateOdometry& m : s.teammate.messages()) {
    if (m.stamp_ns > ToNanoseconds(105.0) && m.stamp_ns < ToNanoseconds(110.0)) continue;  // 5 s without messages
    gappy.Add(m, 60.0);
  }
  MatchingOptions options;
  TrajectoryMatch match;
  ASSERT_TRUE(MatchTrajectory(s.tracker, gappy, options, &match).ok());
  EXPECT_NEAR(match.num_pairs, 240 - 51, 2);
  EXPECT_LT(AngleDeg(s.R_Gi_Gj.transpose() * match.R_Gi_Gj), 0.05);
}

TEST(MatchTrajectory, WindowAndMinimumPairs) {
  const Scenario s = Make(0.0, 0.0, 0.0, 4);
  MatchingOptions options;
  options.window_size = 50;
  TrajectoryMatch match;
  ASSERT_TRUE(MatchTrajectory(s.tracker, s.teammate, options, &match).ok());
  EXPECT_EQ(match.num_pairs, 50);
  OdometryHistory empty;
  EXPECT_FALSE(MatchTrajectory(s.tracker, empty, options, &match).ok());
}

TEST(MatchTrajectory, RefusesAStraightTeammateTrajectory) {
  OdometryHistory line;
  TrajectoryBuffer tracker(300);
  for (int k = 0; k < 100; ++k) {
    TeammateOdometry m;
    m.stamp_ns = ToNanoseconds(0.1 * k);
    m.p_bj_in_Gj = Eigen::Vector3d(0.1 * k, 0.05 * k, 1.0);
    m.v_bj_in_Gj = Eigen::Vector3d(1.0, 0.5, 0.0);
    line.Add(m, 60.0);
    tracker.Push(m.stamp_ns, m.p_bj_in_Gj + Eigen::Vector3d(1, 2, 3));
  }
  TrajectoryMatch match;
  const Status status = MatchTrajectory(tracker, line, MatchingOptions(), &match);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("degenerate"), std::string::npos) << status.message();
}

TEST(MatchTrajectory, AWrongTeammateHasALargeResidual) {
  const Scenario s = Make(0.1, 0.02, 0.0, 5);
  // Another teammate flying a different pattern.
  OdometryHistory other;
  for (int k = 0; k <= 250; ++k) {
    TeammateOdometry m;
    m.stamp_ns = ToNanoseconds(100.0 + 0.1 * k);
    const double t = 0.1 * k;
    m.p_bj_in_Gj = Eigen::Vector3d(std::cos(0.9 * t), 0.8 * std::sin(0.6 * t), 1 + 0.1 * std::sin(t));
    m.v_bj_in_Gj = Eigen::Vector3d(-0.9 * std::sin(0.9 * t), 0.48 * std::cos(0.6 * t), 0.1 * std::cos(t));
    other.Add(m, 60.0);
  }
  MatchingOptions options;
  std::vector<MatchCandidate> candidates(2);
  candidates[0].drone_id = 7;
  candidates[0].valid = MatchTrajectory(s.tracker, other, options, &candidates[0].match).ok();
  candidates[1].drone_id = 3;
  candidates[1].valid = MatchTrajectory(s.tracker, s.teammate, options, &candidates[1].match).ok();
  ASSERT_TRUE(candidates[0].valid && candidates[1].valid);
  EXPECT_GT(candidates[0].match.mean_residual_m, 0.2);
  double second = 0.0;
  EXPECT_EQ(SelectMatch(candidates, options, &second), 1);
  EXPECT_DOUBLE_EQ(second, candidates[0].match.mean_residual_m);
}

TEST(SelectMatch, Rules) {
  MatchingOptions options;  // residual < 0.2 m, runner-up >= 3x
  auto candidate = [](int id, bool valid, double residual) {
    MatchCandidate c;
    c.drone_id = id;
    c.valid = valid;
    c.match.mean_residual_m = residual;
    return c;
  };
  double second = 0.0;
  EXPECT_EQ(SelectMatch({}, options), -1);
  EXPECT_EQ(SelectMatch({candidate(1, true, 0.05)}, options, &second), 0);
  EXPECT_EQ(second, std::numeric_limits<double>::infinity());
  EXPECT_EQ(SelectMatch({candidate(1, true, 0.25)}, options), -1);              // too large
  EXPECT_EQ(SelectMatch({candidate(1, true, 0.05), candidate(2, true, 0.12)}, options), -1);  // ambiguous
  EXPECT_EQ(SelectMatch({candidate(1, true, 0.05), candidate(2, true, 0.4)}, options), 0);
  EXPECT_EQ(SelectMatch({candidate(1, true, 0.4), candidate(2, true, 0.03)}, options), 1);
  EXPECT_EQ(SelectMatch({candidate(1, false, 0.0), candidate(2, true, 0.03)}, options), 1);  // invalid ignored
}

}  // namespace
}  // namespace swarmlio::teammate
