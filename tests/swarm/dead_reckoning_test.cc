// DeadReckoningTrack: the weighted integrals of the own propagated
// accelerations and attitudes over [t_j, t_k] that move the ego position back
// to t_j as a function of the current state (src/swarm/dead_reckoning.h).
#include "src/swarm/dead_reckoning.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "swarmlio/math/so3.h"

namespace swarmlio::swarm::internal {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kStepNs = 5 * kMs;

double Sec(int64_t t_ns) { return 1e-9 * static_cast<double>(t_ns); }

// An accelerating motion p(t) = (sin t, t^2, 0), v = (cos t, 2t, 0),
// a = (-sin t, 2, 0), and a slowly turning attitude R(t) = Exp(0.3 t z).
Eigen::Vector3d Position(double t) { return Eigen::Vector3d(std::sin(t), t * t, 0.0); }
Eigen::Vector3d Velocity(double t) { return Eigen::Vector3d(std::cos(t), 2.0 * t, 0.0); }
Eigen::Vector3d Acceleration(double t) { return Eigen::Vector3d(-std::sin(t), 2.0, 0.0); }
Eigen::Matrix3d Attitude(double t) { return so3::Exp(Eigen::Vector3d(0.0, 0.0, 0.3 * t)); }

// The propagated poses of one scan, every 5 ms on [t0, t1]: pose k holds the
// acceleration and attitude of the interval to pose k + 1 (its midpoint). An
// update before the scan moved the position by `offset`, which must not
// matter: only accelerations enter.
std::vector<lio::ImuPose> Scan(int64_t t0_ns, int64_t t1_ns, const Eigen::Vector3d& offset) {
  std::vector<lio::ImuPose> poses;
  for (int64_t t = t0_ns; t <= t1_ns; t += kStepNs) {
    const double mid = Sec(t) + 0.5 * Sec(kStepNs);
    lio::ImuPose p;
    p.stamp_ns = t;
    p.p_b_in_G = offset + Position(Sec(t));
    p.acc_in_G_m_s2 = Acceleration(mid);
    p.R_G_b = Attitude(mid);
    poses.push_back(p);
  }
  return poses;
}

TEST(DeadReckoningTrack, RetrodictionGivesThePastPositionFromTheCurrentState) {
  DeadReckoningTrack track;
  track.Append(Scan(0, 100 * kMs, Eigen::Vector3d::Zero()), 1.0);
  track.Append(Scan(100 * kMs, 200 * kMs, Eigen::Vector3d(0.03, -0.02, 0.01)), 1.0);
  track.Append(Scan(200 * kMs, 300 * kMs, Eigen::Vector3d(-0.05, 0.04, 0.0)), 1.0);
  const int64_t t_k = 300 * kMs;
  for (const int64_t t_j : {40 * kMs, 100 * kMs, 157 * kMs, 250 * kMs, 300 * kMs}) {
    SCOPED_TRACE(t_j);
    ImuRetrodiction r;
    ASSERT_TRUE(track.Retrodiction(t_j, t_k, &r));
    const double T = Sec(t_k - t_j);
    EXPECT_NEAR(r.weight_s2, 0.5 * T * T, 1e-12);
    // p(t_j) = p(t_k) - v(t_k) T + int (s - t_j) a(s) ds; midpoint rule on
    // 5 ms steps of a smooth motion: well below a micrometre.
    const Eigen::Vector3d past =
        Position(Sec(t_k)) - Velocity(Sec(t_k)) * T + r.weighted_acc_in_G;
    EXPECT_LT((past - Position(Sec(t_j))).norm(), 1e-6);
    // A constant-velocity shift alone misses about 1/2 a T^2 (up to 6.8 cm
    // in y here): the check above would notice a dropped acceleration term.
    if (T > 0.1) {
      EXPECT_GT((Position(Sec(t_k)) - Velocity(Sec(t_k)) * T - Position(Sec(t_j))).norm(), 0.01);
    }
    // The attitude integral: near W R(mid) for a slow turn.
    const Eigen::Matrix3d R_mid = Attitude(0.5 * (Sec(t_j) + Sec(t_k)));
    EXPECT_LT((r.weighted_R_G_b - r.weight_s2 * R_mid).norm(), 0.05 * r.weight_s2 + 1e-12);
  }
  ImuRetrodiction r;
  EXPECT_FALSE(track.Retrodiction(310 * kMs, 300 * kMs, &r));  // t_j after t_k
  EXPECT_FALSE(track.Retrodiction(100 * kMs, 400 * kMs, &r));  // t_k beyond the history
  EXPECT_FALSE(track.Retrodiction(-10 * kMs, 300 * kMs, &r));  // t_j before the history
}

TEST(DeadReckoningTrack, KeepsOnlyTheRequestedSpanAndRestartsWhenTimeGoesBack) {
  DeadReckoningTrack track;
  for (int k = 0; k < 30; ++k) {
    track.Append(Scan(k * 100 * kMs, (k + 1) * 100 * kMs, Eigen::Vector3d::Zero()), 0.5);
  }
  ImuRetrodiction r;
  EXPECT_TRUE(track.Retrodiction(2500 * kMs, 3000 * kMs, &r));
  EXPECT_FALSE(track.Retrodiction(2000 * kMs, 3000 * kMs, &r));  // older than 0.5 s
  EXPECT_LE(track.size(), 110u);
  track.Append(Scan(0, 100 * kMs, Eigen::Vector3d::Zero()), 0.5);  // a new log
  EXPECT_TRUE(track.Retrodiction(0, 100 * kMs, &r));
  EXPECT_FALSE(track.Retrodiction(2500 * kMs, 3000 * kMs, &r));
}

TEST(DeadReckoningTrack, BridgesShortGapsAndRestartsAfterLongOnes) {
  DeadReckoningTrack track;
  track.Append(Scan(0, 100 * kMs, Eigen::Vector3d::Zero()), 1.0);
  track.Append(Scan(110 * kMs, 200 * kMs, Eigen::Vector3d::Zero()), 1.0);  // 10 ms gap
  ImuRetrodiction r;
  EXPECT_TRUE(track.Retrodiction(50 * kMs, 200 * kMs, &r));
  EXPECT_NEAR(r.weight_s2, 0.5 * 0.15 * 0.15, 1e-12);
  track.Append(Scan(300 * kMs, 400 * kMs, Eigen::Vector3d::Zero()), 1.0);  // 100 ms gap
  EXPECT_FALSE(track.Retrodiction(150 * kMs, 400 * kMs, &r));
  EXPECT_TRUE(track.Retrodiction(300 * kMs, 400 * kMs, &r));
}

}  // namespace
}  // namespace swarmlio::swarm::internal
