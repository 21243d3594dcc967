#include "swarmlio/sim/imu_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "swarmlio/math/so3.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

Trajectory Flight() {
  TrajectoryBuilderOptions opt;
  opt.max_speed_m_s = 2.0;
  TrajectoryBuilder b(Eigen::Vector3d(0, 0, 0.2), 0.5, opt, 11);
  b.Hover(3.0);
  b.Takeoff(1.5);
  b.Excite(10.0, Eigen::Vector3d(1.5, 1.5, 0.5), 0.8, 2.0);
  return b.Build(0.0, 20.0);
}

struct NavState {
  Eigen::Quaterniond q;
  Eigen::Vector3d p, v;
};

// Time derivative of the navigation state for body rate w and specific force f.
void Rates(const NavState& x, const Eigen::Vector3d& w, const Eigen::Vector3d& f,
           Eigen::Vector4d* dq, Eigen::Vector3d* dp, Eigen::Vector3d* dv) {
  const Eigen::Quaterniond qw = x.q * Eigen::Quaterniond(0, w.x(), w.y(), w.z());
  *dq = 0.5 * qw.coeffs();
  *dp = x.v;
  *dv = x.q.toRotationMatrix() * f + Eigen::Vector3d(0, 0, -kGravity);
}

NavState Add(const NavState& x, const Eigen::Vector4d& dq, const Eigen::Vector3d& dp,
             const Eigen::Vector3d& dv, double h) {
  NavState y;
  y.q.coeffs() = x.q.coeffs() + h * dq;
  y.p = x.p + h * dp;
  y.v = x.v + h * dv;
  return y;
}

// ACCEPTANCE: a noise-free IMU at 400 Hz, integrated with RK4 over steps of two
// samples (the middle sample is the RK4 midpoint), reproduces the true pose.
TEST(ImuModel, NoiseFreeIntegrationReproducesTruePose) {
  const Trajectory traj = Flight();
  SimulatedImuOptions opt;
  opt.noise_enabled = false;
  opt.sensor.rate_hz = 400.0;
  const double t0 = 4.0;  // start in flight, after take-off began
  ImuModel imu(opt, &traj, t0, 1);
  std::vector<ImuMeasurement> samples;
  for (int k = 0; k <= 4000; ++k) samples.push_back(imu.Next());  // 10 s
  const KinematicState s0 = traj.StateAt(t0);
  NavState x{Eigen::Quaterniond(s0.R_W_b), s0.p_b_in_W, s0.v_b_in_W};
  double max_pos_err = 0.0, max_rot_err = 0.0;
  for (size_t k = 0; k + 2 < samples.size() + 1; k += 2) {
    const double h = samples[k + 2].t - samples[k].t;
    const ImuMeasurement& a = samples[k];
    const ImuMeasurement& m = samples[k + 1];
    const ImuMeasurement& b = samples[k + 2];
    Eigen::Vector4d q1, q2, q3, q4;
    Eigen::Vector3d p1, p2, p3, p4, v1, v2, v3, v4;
    Rates(x, a.gyro, a.accel, &q1, &p1, &v1);
    Rates(Add(x, q1, p1, v1, h / 2), m.gyro, m.accel, &q2, &p2, &v2);
    Rates(Add(x, q2, p2, v2, h / 2), m.gyro, m.accel, &q3, &p3, &v3);
    Rates(Add(x, q3, p3, v3, h), b.gyro, b.accel, &q4, &p4, &v4);
    x.q.coeffs() += h / 6 * (q1 + 2 * q2 + 2 * q3 + q4);
    x.q.normalize();
    x.p += h / 6 * (p1 + 2 * p2 + 2 * p3 + p4);
    x.v += h / 6 * (v1 + 2 * v2 + 2 * v3 + v4);
    const Pose truth = traj.PoseAt(b.t);
    max_pos_err = std::max(max_pos_err, (x.p - truth.p_b_in_W).norm());
    max_rot_err = std::max(max_rot_err,
                           so3::Log(Eigen::Matrix3d(truth.R_W_b.transpose() * x.q.toRotationMatrix())).norm());
    if (k + 2 == samples.size() - 1) break;
  }
  EXPECT_LT(max_pos_err, 1e-3);
  EXPECT_LT(max_rot_err * 180.0 / M_PI, 0.01);
  // The flight really moved.
  EXPECT_GT((traj.PositionAt(t0 + 10.0) - traj.PositionAt(t0)).norm() +
                (traj.PositionAt(t0 + 5.0) - traj.PositionAt(t0)).norm(),
            0.5);
  RecordProperty("max_position_error_m", std::to_string(max_pos_err));
  RecordProperty("max_rotation_error_deg", std::to_string(max_rot_err * 180.0 / M_PI));
  std::printf("IMU RK4 over 10 s: max position error %.3g m, max rotation error %.3g deg\n",
              max_pos_err, max_rot_err * 180.0 / M_PI);
}

TEST(ImuModel, StaticGyroMeanRecoversBias) {
  const Trajectory traj = Flight();
  SimulatedImuOptions opt;
  ImuModel imu(opt, &traj, 0.0, 99);
  const int n = 600;  // the 3 s static start at 200 Hz
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero(), bias_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero(), accel_bias_sum = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    const ImuMeasurement m = imu.Next();
    EXPECT_LT(m.true_gyro.norm(), 1e-12);
    gyro_sum += m.gyro;
    bias_sum += m.gyro_bias;
    accel_sum += m.accel - m.true_accel;
    accel_bias_sum += m.accel_bias;
  }
  const double sqrt_rate = std::sqrt(opt.sensor.rate_hz);
  const double sigma_mean = opt.sensor.gyro_noise_density_rad_s_sqrt_hz * sqrt_rate / std::sqrt(n);
  const Eigen::Vector3d err = (gyro_sum - bias_sum) / n;
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(err[i]), 3.0 * sigma_mean) << i;
  const double sigma_a = opt.sensor.accel_noise_density_m_s2_sqrt_hz * sqrt_rate / std::sqrt(n);
  const Eigen::Vector3d err_a = (accel_sum - accel_bias_sum) / n;
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(err_a[i]), 3.0 * sigma_a) << i;
  // The bias itself is non-trivial compared to the averaging noise.
  EXPECT_GT((bias_sum / n).norm(), 3.0 * sigma_mean);
  // Static specific force is +g along body z (gravity-aligned start).
  SimulatedImuOptions clean;
  clean.noise_enabled = false;
  ImuModel ideal(clean, &traj, 0.0, 1);
  EXPECT_LT((ideal.Next().accel - Eigen::Vector3d(0, 0, clean.sensor.gravity_m_s2)).norm(), 1e-12);
}

TEST(ImuModel, SameSeedSameNoise) {
  const Trajectory traj = Flight();
  ImuModel a(SimulatedImuOptions(), &traj, 0.0, 5), b(SimulatedImuOptions(), &traj, 0.0, 5);
  for (int k = 0; k < 50; ++k) EXPECT_EQ(a.Next().gyro, b.Next().gyro);
}

// The sensor description's unit and gravity: a Livox built-in IMU reports g,
// and ImuOptions::AccelerationToMetersPerSecondSquared() converts it back.
TEST(ImuModel, HonoursAccelerationUnitAndGravity) {
  const Trajectory traj = Flight();
  SimulatedImuOptions opt;
  opt.sensor.gravity_m_s2 = 9.80665;
  ImuModel in_m_s2(opt, &traj, 0.0, 7);
  opt.sensor.acceleration_unit = AccelerationUnit::kStandardGravity;
  ImuModel in_g(opt, &traj, 0.0, 7);
  const ImuMeasurement first = in_g.Next();
  EXPECT_LT((first.true_accel - Eigen::Vector3d(0, 0, 9.80665)).norm(), 1e-12);  // static start
  EXPECT_NEAR(first.accel.z(), 1.0, 0.05);                       // 1 g plus bias and noise
  in_m_s2.Next();
  for (int k = 0; k < 1000; ++k) {
    const ImuMeasurement g = in_g.Next();
    const ImuMeasurement m = in_m_s2.Next();
    EXPECT_EQ(g.gyro, m.gyro);  // same random stream
    EXPECT_LT((g.accel * opt.sensor.AccelerationToMetersPerSecondSquared() - m.accel).norm(),
              1e-12);
  }
}

}  // namespace
}  // namespace swarmlio::sim
