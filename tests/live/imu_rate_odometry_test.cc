// ImuRateOdometry: nothing before a scan posterior; constant velocity and a
// constant turn are propagated exactly; a later posterior re-propagates the
// samples already received after it; the IMU time offset is applied.
#include "swarmlio/live/imu_rate_odometry.h"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmlio::live {
namespace {

constexpr int64_t kStep = 5'000'000;  // 200 Hz

ImuSample Sample(int64_t stamp_ns, const Eigen::Vector3d& w) {
  ImuSample s;
  s.stamp_ns = stamp_ns;
  s.angular_velocity_rad_s = w;
  s.linear_acceleration = Eigen::Vector3d(0, 0, 1.0);  // in g: hovering (unit factor 9.81)
  return s;
}

EgoState Moving() {
  EgoState x;
  x.p_b_in_G = Eigen::Vector3d(1, 2, 3);
  x.v_b_in_G = Eigen::Vector3d(0.5, -0.2, 0.1);
  return x;
}

TEST(ImuRateOdometry, ConstantVelocityAtEverySample) {
  ImuRateOdometry odom(0);
  ImuRatePose pose;
  EXPECT_FALSE(odom.AddImu(Sample(0, Eigen::Vector3d::Zero()), 9.81, &pose));  // no posterior yet
  odom.ResetToScan(Moving(), 0, 9.81);
  for (int k = 1; k <= 40; ++k) {
    ASSERT_TRUE(odom.AddImu(Sample(k * kStep, Eigen::Vector3d::Zero()), 9.81, &pose));
    const double t = 1e-9 * static_cast<double>(k * kStep);
    EXPECT_EQ(pose.stamp_ns, k * kStep);
    EXPECT_LT((pose.p_b_in_G - (Moving().p_b_in_G + t * Moving().v_b_in_G)).norm(), 1e-9);
    EXPECT_LT((pose.v_b_in_G - Moving().v_b_in_G).norm(), 1e-9);
  }
}

TEST(ImuRateOdometry, ConstantTurnAndRePropagationAfterALatePosterior) {
  const Eigen::Vector3d w(0, 0, 0.4);  // rad/s about z
  ImuRateOdometry odom(0);
  ImuRatePose pose;
  odom.ResetToScan(EgoState(), 0, 9.81);
  for (int k = 1; k <= 20; ++k) ASSERT_TRUE(odom.AddImu(Sample(k * kStep, w), 9.81, &pose));
  // The posterior of a scan ending at 50 ms arrives now (after sample 20 = 100 ms).
  EgoState at_50ms;
  at_50ms.p_b_in_G = Eigen::Vector3d(10, 0, 0);
  at_50ms.q_G_b = Eigen::Quaterniond(Eigen::AngleAxisd(0.4 * 0.05, Eigen::Vector3d::UnitZ()));
  odom.ResetToScan(at_50ms, 50'000'000, 9.81);
  ASSERT_TRUE(odom.AddImu(Sample(21 * kStep, w), 9.81, &pose));
  EXPECT_EQ(pose.stamp_ns, 21 * kStep);
  EXPECT_LT((pose.p_b_in_G - Eigen::Vector3d(10, 0, 0)).norm(), 1e-9);  // hovering
  const double yaw = 2.0 * std::atan2(pose.q_G_b.z(), pose.q_G_b.w());
  EXPECT_NEAR(yaw, 0.4 * 0.105, 1e-9);
  EXPECT_LT((pose.angular_velocity_in_b_rad_s - w).norm(), 1e-12);
}

TEST(ImuRateOdometry, TimeOffsetAndOutOfOrderSamples) {
  ImuRateOdometry odom(2'000'000);  // IMU stamps 2 ms late
  ImuRatePose pose;
  odom.ResetToScan(Moving(), 0, 9.81);
  ASSERT_TRUE(odom.AddImu(Sample(kStep + 2'000'000, Eigen::Vector3d::Zero()), 9.81, &pose));
  EXPECT_EQ(pose.stamp_ns, kStep);
  EXPECT_FALSE(odom.AddImu(Sample(kStep + 2'000'000, Eigen::Vector3d::Zero()), 9.81, &pose));
  ImuSample bad = Sample(3 * kStep, Eigen::Vector3d::Zero());
  bad.linear_acceleration.x() = std::nan("");
  EXPECT_FALSE(odom.AddImu(bad, 9.81, &pose));
}

}  // namespace
}  // namespace swarmlio::live
