#include "swarmlio/lio/in_flight_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

constexpr int64_t kT0Ns = 5'000'000'000;
constexpr int64_t kImuPeriodNs = 5'000'000;  // 200 Hz
constexpr int64_t kScanPeriodNs = 100'000'000;

// A body flying in the world W: a smooth acceleration, a constant body rate
// about a tilted axis, and a tilted start. G is the IMU frame at t0, so the
// truth in G is v0 = R_W_b0^T v_W(t0), g = R_W_b0^T g_W.
struct Flight {
  Eigen::Vector3d g_W{0.0, 0.0, -9.81};
  Eigen::Vector3d v0_W{1.2, -0.4, 0.3};
  Eigen::Vector3d w_b{0.3, -0.2, 0.8};  // [rad/s]
  Eigen::Matrix3d R_W_b0 = so3::Exp(Eigen::Vector3d(0.1, -0.15, 0.7));

  Eigen::Vector3d Acceleration(double t) const {  // in W
    return Eigen::Vector3d(1.5 * std::sin(2.0 * t), -1.0 * std::cos(3.0 * t), 0.8 * std::sin(t));
  }
  Eigen::Vector3d Velocity(double t) const {
    return v0_W + Eigen::Vector3d(0.75 * (1.0 - std::cos(2.0 * t)), -std::sin(3.0 * t) / 3.0,
                                  0.8 * (1.0 - std::cos(t)));
  }
  Eigen::Vector3d Position(double t) const {
    return v0_W * t + Eigen::Vector3d(0.75 * (t - std::sin(2.0 * t) / 2.0),
                                      (std::cos(3.0 * t) - 1.0) / 9.0, 0.8 * (t - std::sin(t)));
  }
  Eigen::Matrix3d R_W_b(double t) const { return R_W_b0 * so3::Exp(t * w_b); }

  // `scale`: reported = scale * specific force (1 / 9.81 for g units).
  ImuSample Sample(int64_t stamp_ns, double scale = 1.0) const {
    const double t = 1e-9 * static_cast<double>(stamp_ns - kT0Ns);
    ImuSample s;
    s.stamp_ns = stamp_ns;
    s.angular_velocity_rad_s = w_b;
    s.linear_acceleration = scale * R_W_b(t).transpose() * (Acceleration(t) - g_W);
    return s;
  }
  Eigen::Vector3d PositionInG(double t) const {
    return R_W_b0.transpose() * (Position(t) - Position(0.0));
  }
};

struct Data {
  ImuSample start;
  std::vector<ImuSample> samples;
  std::vector<StampedPose> positions;
};

Data Make(const Flight& f, double duration_s, double noise_m, double scale = 1.0) {
  Data d;
  d.start = f.Sample(kT0Ns, scale);
  const int64_t end_ns = kT0Ns + static_cast<int64_t>(duration_s * 1e9);
  for (int64_t t = kT0Ns + kImuPeriodNs; t <= end_ns + kImuPeriodNs; t += kImuPeriodNs) {
    d.samples.push_back(f.Sample(t, scale));
  }
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  // Scan ends off the IMU grid (sub-stepped integration).
  for (int64_t t = kT0Ns + kScanPeriodNs + 1'234'567; t <= end_ns; t += kScanPeriodNs) {
    StampedPose p;
    p.stamp_ns = t;
    const double tau = 1e-9 * static_cast<double>(t - kT0Ns);
    p.p_b_in_G = f.PositionInG(tau) + noise_m * Eigen::Vector3d(n(rng), n(rng), n(rng));
    p.q_G_b = Eigen::Quaterniond(f.R_W_b0.transpose() * f.R_W_b(tau));
    d.positions.push_back(p);
  }
  return d;
}

TEST(InFlightAlignment, RecoversVelocityAndGravityOfAnAcceleratingTurningBody) {
  const Flight f;
  const Data d = Make(f, 1.5, 0.0);
  VelocityGravityAlignment a;
  const Status s = AlignVelocityAndGravity(d.start, d.samples, 1.0, Eigen::Vector3d::Zero(),
                                           d.positions, 0.01, &a);
  ASSERT_TRUE(s.ok()) << s.message();
  const Eigen::Vector3d v_true = f.R_W_b0.transpose() * f.Velocity(0.0);
  const Eigen::Vector3d g_true = f.R_W_b0.transpose() * f.g_W;
  EXPECT_EQ(a.num_positions, 14);
  EXPECT_LT((a.v_b_in_G - v_true).norm(), 1e-3) << a.v_b_in_G.transpose();
  EXPECT_LT((a.g_in_G - g_true).norm(), 5e-3) << a.g_in_G.transpose();
  EXPECT_LT(a.rms_residual_m, 1e-4);
  // The rms is below the floor: the covariance uses the floor.
  EXPECT_GT(a.covariance(3, 3), 0.0);
  EXPECT_TRUE(a.covariance.isApprox(a.covariance.transpose()));
}

TEST(InFlightAlignment, TheCovarianceCoversTheErrorOfNoisyPositions) {
  const Flight f;
  const Eigen::Vector3d v_true = f.R_W_b0.transpose() * f.Velocity(0.0);
  const Eigen::Vector3d g_true = f.R_W_b0.transpose() * f.g_W;
  const Data d = Make(f, 1.5, 0.005);
  VelocityGravityAlignment a;
  ASSERT_TRUE(AlignVelocityAndGravity(d.start, d.samples, 1.0, Eigen::Vector3d::Zero(), d.positions,
                                      0.001, &a)
                  .ok());
  EXPECT_NEAR(a.rms_residual_m, 0.005, 0.002);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(a.v_b_in_G(k) - v_true(k)), 4.0 * std::sqrt(a.covariance(k, k))) << k;
    EXPECT_LT(std::abs(a.g_in_G(k) - g_true(k)), 4.0 * std::sqrt(a.covariance(3 + k, 3 + k))) << k;
  }
  // About 0.2 deg of tilt from 5 mm positions over 1.5 s.
  EXPECT_LT(std::sqrt(a.covariance(3, 3)), 0.05);
}

TEST(InFlightAlignment, UsesTheUnitFactorAndTheGyro) {
  const Flight f;
  const Eigen::Vector3d g_true = f.R_W_b0.transpose() * f.g_W;
  // Samples in g units with the factor 9.81: the same solution.
  const Data in_g = Make(f, 1.5, 0.0, 1.0 / 9.81);
  VelocityGravityAlignment a;
  ASSERT_TRUE(AlignVelocityAndGravity(in_g.start, in_g.samples, 9.81, Eigen::Vector3d::Zero(),
                                      in_g.positions, 0.01, &a)
                  .ok());
  EXPECT_LT((a.g_in_G - g_true).norm(), 5e-3);
  // A sign-flipped factor or a wrong gyro bias cannot explain the positions
  // (the bias acts between the scan rotations: 1 rad/s turns 0.1 rad per scan).
  const Data d = Make(f, 1.5, 0.0);
  ASSERT_TRUE(AlignVelocityAndGravity(d.start, d.samples, -1.0, Eigen::Vector3d::Zero(),
                                      d.positions, 0.01, &a)
                  .ok());
  EXPECT_GT((a.g_in_G - g_true).norm(), 1.0);
  EXPECT_GT(a.rms_residual_m, 0.01);
  ASSERT_TRUE(AlignVelocityAndGravity(d.start, d.samples, 1.0, Eigen::Vector3d(0.0, 1.0, 0.0),
                                      d.positions, 0.01, &a)
                  .ok());
  EXPECT_GT((a.g_in_G - g_true).norm(), 0.1);
}

TEST(InFlightAlignment, RefusesTooFewOrTooClosePositions) {
  const Flight f;
  Data d = Make(f, 1.5, 0.0);
  VelocityGravityAlignment a;
  std::vector<StampedPose> two(d.positions.begin(), d.positions.begin() + 2);
  EXPECT_EQ(AlignVelocityAndGravity(d.start, d.samples, 1.0, Eigen::Vector3d::Zero(), two, 0.01, &a)
                .code(),
            Status::Code::kFailedPrecondition);
  std::vector<StampedPose> close(3, d.positions.front());
  close[1].stamp_ns += 1'000'000;
  close[2].stamp_ns += 2'000'000;
  EXPECT_EQ(
      AlignVelocityAndGravity(d.start, d.samples, 1.0, Eigen::Vector3d::Zero(), close, 0.01, &a)
          .code(),
      Status::Code::kFailedPrecondition);
  // A position after the last IMU sample cannot be integrated.
  std::vector<StampedPose> late = d.positions;
  late.back().stamp_ns = d.samples.back().stamp_ns + 1;
  EXPECT_EQ(
      AlignVelocityAndGravity(d.start, d.samples, 1.0, Eigen::Vector3d::Zero(), late, 0.01, &a)
          .code(),
      Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::lio
