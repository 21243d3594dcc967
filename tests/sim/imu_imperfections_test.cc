// Statistical tests of the IMU imperfections (ImuImperfectionOptions):
// vibration amplitudes from a least-squares fit, scale/misalignment spreads
// over many drones, quantisation steps, dropout rate and stamp jitter.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "swarmlio/sim/imu_model.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

Trajectory Flight() {
  TrajectoryBuilderOptions opt;
  opt.max_speed_m_s = 2.0;
  TrajectoryBuilder b(Eigen::Vector3d(0, 0, 0.2), 0.5, opt, 11);
  b.Hover(3.0);
  b.Takeoff(1.5);
  b.Excite(20.0, Eigen::Vector3d(1.5, 1.5, 0.5), 0.8, 2.0);
  return b.Build(0.0, 30.0);
}

double Std(const std::vector<double>& x) {
  double mean = 0.0, sq = 0.0;
  for (double v : x) mean += v;
  mean /= x.size();
  for (double v : x) sq += (v - mean) * (v - mean);
  return std::sqrt(sq / (x.size() - 1));
}

// Rotor vibration: a least-squares fit of sinusoids at the rotor frequency
// and its harmonic to (measured - true - bias), white noise on, recovers each
// axis' amplitudes within 10 % and the drawn phases.
TEST(ImuImperfections, VibrationAmplitudesFromAFit) {
  const Trajectory traj = Flight();
  SimulatedImuOptions o;
  ImuImperfectionOptions& v = o.imperfections;
  v.rotor_frequency_hz = 173.0;
  v.rotor_harmonic = 2;
  v.accel_vibration_m_s2 = Eigen::Vector3d(0.2, 0.3, 0.5);
  v.accel_vibration_harmonic_m_s2 = Eigen::Vector3d(0.05, 0.1, 0.15);
  v.gyro_vibration_rad_s = Eigen::Vector3d(0.01, 0.02, 0.03);
  v.gyro_vibration_harmonic_rad_s = Eigen::Vector3d(0.004, 0.005, 0.006);
  ImuModel imu(o, &traj, 0.0, 21);
  const int n = 5000;  // 25 s at 200 Hz, static and flying
  Eigen::MatrixXd basis(n, 5);
  Eigen::MatrixXd gyro(n, 3), accel(n, 3);
  const double omega = 2.0 * M_PI * v.rotor_frequency_hz;
  for (int k = 0; k < n; ++k) {
    const ImuMeasurement m = imu.Next();
    basis.row(k) << std::sin(omega * m.t), std::cos(omega * m.t), std::sin(2 * omega * m.t),
        std::cos(2 * omega * m.t), 1.0;
    gyro.row(k) = (m.gyro - m.true_gyro - m.gyro_bias).transpose();
    accel.row(k) = (m.accel - m.true_accel - m.accel_bias).transpose();
  }
  const Eigen::MatrixXd fit_g = basis.colPivHouseholderQr().solve(gyro);
  const Eigen::MatrixXd fit_a = basis.colPivHouseholderQr().solve(accel);
  const ImuErrors& e = imu.errors();
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    // A sin(wt + phi) = A cos(phi) sin(wt) + A sin(phi) cos(wt).
    EXPECT_NEAR(std::hypot(fit_g(0, i), fit_g(1, i)) / v.gyro_vibration_rad_s[i], 1.0, 0.1);
    EXPECT_NEAR(std::hypot(fit_g(2, i), fit_g(3, i)) / v.gyro_vibration_harmonic_rad_s[i], 1.0,
                0.1);
    EXPECT_NEAR(std::hypot(fit_a(0, i), fit_a(1, i)) / v.accel_vibration_m_s2[i], 1.0, 0.1);
    EXPECT_NEAR(std::hypot(fit_a(2, i), fit_a(3, i)) / v.accel_vibration_harmonic_m_s2[i], 1.0,
                0.1);
    const double phase = std::atan2(fit_a(1, i), fit_a(0, i));
    EXPECT_NEAR(std::remainder(phase - e.accel_phase_rad[i], 2 * M_PI), 0.0, 0.1);
  }
}

// Scale factor and misalignment: drawn once per drone from its seed (std of
// the diagonal - 1 and of the off-diagonal elements within 10 % of the
// settings over 2000 drones); the output is exactly M * truth without noise.
TEST(ImuImperfections, ScaleAndMisalignmentPerDroneFromTheSeed) {
  SimulatedImuOptions o;
  o.imperfections.gyro_scale_factor_sigma = 0.01;
  o.imperfections.gyro_misalignment_sigma_rad = 0.003;
  o.imperfections.accel_scale_factor_sigma = 0.004;
  o.imperfections.accel_misalignment_sigma_rad = 0.002;
  std::vector<double> gs, gm, as, am;
  for (uint64_t seed = 0; seed < 2000; ++seed) {
    const ImuErrors e = ImuModel::DrawErrors(o, seed);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        (r == c ? gs : gm).push_back(e.gyro_matrix(r, c) - (r == c));
        (r == c ? as : am).push_back(e.accel_matrix(r, c) - (r == c));
      }
    }
  }
  EXPECT_NEAR(Std(gs) / 0.01, 1.0, 0.1);
  EXPECT_NEAR(Std(gm) / 0.003, 1.0, 0.1);
  EXPECT_NEAR(Std(as) / 0.004, 1.0, 0.1);
  EXPECT_NEAR(Std(am) / 0.002, 1.0, 0.1);
  // Same seed, same drone; another seed, another drone.
  EXPECT_EQ(ImuModel::DrawErrors(o, 5).gyro_matrix, ImuModel::DrawErrors(o, 5).gyro_matrix);
  EXPECT_NE(ImuModel::DrawErrors(o, 5).gyro_matrix, ImuModel::DrawErrors(o, 6).gyro_matrix);

  const Trajectory traj = Flight();
  o.noise_enabled = false;
  ImuModel imu(o, &traj, 4.0, 3);
  for (int k = 0; k < 400; ++k) {
    const ImuMeasurement m = imu.Next();
    ASSERT_LT((m.gyro - imu.errors().gyro_matrix * m.true_gyro).norm(), 1e-12);
    ASSERT_LT((m.accel - imu.errors().accel_matrix * m.true_accel).norm(), 1e-12);
  }
}

// Quantisation: every output is an exact multiple of its LSB (in m/s^2 also
// when written in g), within half an LSB of the unquantised value.
TEST(ImuImperfections, QuantisedToExactMultiplesOfTheLsb) {
  const Trajectory traj = Flight();
  SimulatedImuOptions o;
  o.imperfections.gyro_lsb_rad_s = 2000.0 / 32768.0 * M_PI / 180.0;
  o.imperfections.accel_lsb_m_s2 = 24.0 * 9.80665 / 32768.0;
  const double lsb_g = o.imperfections.gyro_lsb_rad_s, lsb_a = o.imperfections.accel_lsb_m_s2;
  for (AccelerationUnit unit :
       {AccelerationUnit::kMetersPerSecondSquared, AccelerationUnit::kStandardGravity}) {
    o.sensor.acceleration_unit = unit;
    const double to_m_s2 = o.sensor.AccelerationToMetersPerSecondSquared();
    ImuModel imu(o, &traj, 0.0, 8);
    for (int k = 0; k < 2000; ++k) {
      const ImuMeasurement m = imu.Next();
      for (int i = 0; i < 3; ++i) {
        const double g = m.gyro[i] / lsb_g, a = m.accel[i] * to_m_s2 / lsb_a;
        ASSERT_NEAR(g, std::round(g), 1e-6);
        ASSERT_NEAR(a, std::round(a), 1e-6);
      }
    }
  }
  // Without noise: within half a step of the truth.
  o.noise_enabled = false;
  o.sensor.acceleration_unit = AccelerationUnit::kMetersPerSecondSquared;
  ImuModel clean(o, &traj, 4.0, 8);
  double max_g = 0.0, max_a = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const ImuMeasurement m = clean.Next();
    max_g = std::max(max_g, (m.gyro - m.true_gyro).cwiseAbs().maxCoeff());
    max_a = std::max(max_a, (m.accel - m.true_accel).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(max_g, 0.5 * lsb_g + 1e-12);
  EXPECT_LE(max_a, 0.5 * lsb_a + 1e-12);
  EXPECT_GT(max_g, 0.4 * lsb_g);  // really quantised
  EXPECT_GT(max_a, 0.4 * lsb_a);
}

// Sample dropouts within 3 sigma of the binomial; stamp jitter std within
// 10 % of the setting, zero mean; neither touches the noise stream.
TEST(ImuImperfections, DropoutRateAndStampJitter) {
  const Trajectory traj = Flight();
  SimulatedImuOptions o;
  o.imperfections.sample_dropout_probability = 0.05;
  o.imperfections.timestamp_jitter_s = 2e-4;
  ImuModel imu(o, &traj, 0.0, 4);
  ImuModel plain(SimulatedImuOptions(), &traj, 0.0, 4);
  const int n = 20000;
  int dropped = 0;
  std::vector<double> jitter;
  for (int k = 0; k < n; ++k) {
    const ImuMeasurement m = imu.Next();
    const ImuMeasurement p = plain.Next();
    ASSERT_EQ(m.gyro, p.gyro);  // same noise draws
    dropped += m.dropped;
    jitter.push_back(m.stamp_jitter_s);
    ASSERT_LE(std::abs(m.stamp_jitter_s), 0.25 / o.sensor.rate_hz);
    EXPECT_FALSE(p.dropped);
    EXPECT_EQ(p.stamp_jitter_s, 0.0);
  }
  EXPECT_LT(std::abs(dropped - 0.05 * n), 3.0 * std::sqrt(n * 0.05 * 0.95));
  EXPECT_NEAR(Std(jitter) / 2e-4, 1.0, 0.1);
  double mean = 0.0;
  for (double j : jitter) mean += j / n;
  EXPECT_LT(std::abs(mean), 4.0 * 2e-4 / std::sqrt(n));
}

}  // namespace
}  // namespace swarmlio::sim
