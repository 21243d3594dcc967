// DeadReckoningTrack: chains the propagated positions of consecutive scans
// without the updates' corrections and gives s(t_j) - s(t_k).
#include "src/swarm/dead_reckoning.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace swarmlio::swarm::internal {
namespace {

constexpr int64_t kMs = 1'000'000;

// Poses every 5 ms on [t0, t1] of p(t) = offset + (sin t, t^2, 0) (an
// accelerating motion), shifted by `offset` (an update's correction).
std::vector<ImuPose> Scan(int64_t t0_ns, int64_t t1_ns, const Eigen::Vector3d& offset) {
  std::vector<ImuPose> poses;
  for (int64_t t = t0_ns; t <= t1_ns; t += 5 * kMs) {
    const double s = 1e-9 * static_cast<double>(t);
    ImuPose p;
    p.stamp_ns = t;
    p.p_b_in_G = offset + Eigen::Vector3d(std::sin(s), s * s, 0.0);
    poses.push_back(p);
  }
  return poses;
}

Eigen::Vector3d Truth(int64_t t_ns) {
  const double s = 1e-9 * static_cast<double>(t_ns);
  return Eigen::Vector3d(std::sin(s), s * s, 0.0);
}

TEST(DeadReckoningTrack, DisplacementIgnoresTheUpdatesJumps) {
  DeadReckoningTrack track;
  // Three scans of 100 ms; each starts at the previous end, after an update
  // that moved the position by a few centimetres.
  track.Append(Scan(0, 100 * kMs, Eigen::Vector3d::Zero()), 1.0);
  track.Append(Scan(100 * kMs, 200 * kMs, Eigen::Vector3d(0.03, -0.02, 0.01)), 1.0);
  track.Append(Scan(200 * kMs, 300 * kMs, Eigen::Vector3d(-0.05, 0.04, 0.0)), 1.0);
  Eigen::Vector3d d;
  for (const int64_t t_j : {40 * kMs, 100 * kMs, 155 * kMs, 250 * kMs, 300 * kMs}) {
    ASSERT_TRUE(track.Displacement(t_j, 300 * kMs, &d));
    // Linear interpolation between 5 ms samples of a smooth curve: ~1e-5 m.
    EXPECT_LT((d - (Truth(t_j) - Truth(300 * kMs))).norm(), 2e-5) << t_j;
  }
  // The constant-velocity shift misses the acceleration: this test's motion
  // would be off by (1/2) a dt^2 = 0.26 mm over 0.26 s at 2 m/s^2 in y.
  EXPECT_FALSE(track.Displacement(310 * kMs, 300 * kMs, &d));  // t_j after t_k
  EXPECT_FALSE(track.Displacement(100 * kMs, 400 * kMs, &d));   // t_k beyond the track
  EXPECT_FALSE(track.Displacement(-10 * kMs, 300 * kMs, &d));   // t_j before the track
}

TEST(DeadReckoningTrack, KeepsOnlyTheRequestedSpanAndRestartsWhenTimeGoesBack) {
  DeadReckoningTrack track;
  for (int k = 0; k < 30; ++k) {
    track.Append(Scan(k * 100 * kMs, (k + 1) * 100 * kMs, Eigen::Vector3d::Zero()), 0.5);
  }
  Eigen::Vector3d d;
  EXPECT_TRUE(track.Displacement(2500 * kMs, 3000 * kMs, &d));
  EXPECT_FALSE(track.Displacement(2000 * kMs, 3000 * kMs, &d));  // older than 0.5 s
  EXPECT_LE(track.size(), 110u);
  track.Append(Scan(0, 100 * kMs, Eigen::Vector3d::Zero()), 0.5);  // a new log
  EXPECT_TRUE(track.Displacement(0, 100 * kMs, &d));
  EXPECT_FALSE(track.Displacement(2500 * kMs, 3000 * kMs, &d));
}

}  // namespace
}  // namespace swarmlio::swarm::internal
