#include "swarmlio/sim/imu_model.h"

#include <cmath>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {

void IdealImu(const Trajectory& trajectory, double t, double gravity_m_s2,
              Eigen::Vector3d* omega_b, Eigen::Vector3d* specific_force_b) {
  const KinematicState s = trajectory.StateAt(t);
  *omega_b = s.omega_b;
  *specific_force_b = s.R_W_b.transpose() * (s.a_b_in_W + Eigen::Vector3d(0, 0, gravity_m_s2));
}

ImuModel::ImuModel(const SimulatedImuOptions& options, const Trajectory* trajectory, double t0_s,
                   uint64_t seed)
    : options_(options), trajectory_(trajectory), t0_(t0_s), rng_(seed) {
  CHECK(trajectory_ != nullptr);
  CHECK(options_.Validate().empty()) << options_.Validate();
  auto random_vector = [&](double sigma) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = sigma * normal_(rng_);
    return v;
  };
  gyro_bias_ = Eigen::Vector3d::Zero();
  accel_bias_ = Eigen::Vector3d::Zero();
  if (options_.noise_enabled) {
    gyro_bias_ = random_vector(options_.gyro_bias_initial_sigma_rad_s);
    accel_bias_ = random_vector(options_.accel_bias_initial_sigma_m_s2);
  }
}

double ImuModel::next_time() const {
  return t0_ + static_cast<double>(index_) / options_.sensor.rate_hz;
}

ImuMeasurement ImuModel::Next() {
  ImuMeasurement m;
  m.t = next_time();
  const ImuOptions& sensor = options_.sensor;
  IdealImu(*trajectory_, m.t, sensor.gravity_m_s2, &m.true_gyro, &m.true_accel);
  m.gyro = m.true_gyro;
  m.accel = m.true_accel;
  if (options_.noise_enabled) {
    const double sqrt_rate = std::sqrt(sensor.rate_hz);
    const double sigma_g = sensor.gyro_noise_density_rad_s_sqrt_hz * sqrt_rate;
    const double sigma_a = sensor.accel_noise_density_m_s2_sqrt_hz * sqrt_rate;
    const double walk_g = sensor.gyro_bias_random_walk_rad_s2_sqrt_hz / sqrt_rate;
    const double walk_a = sensor.accel_bias_random_walk_m_s3_sqrt_hz / sqrt_rate;
    m.gyro_bias = gyro_bias_;
    m.accel_bias = accel_bias_;
    for (int i = 0; i < 3; ++i) {
      m.gyro[i] += gyro_bias_[i] + sigma_g * normal_(rng_);
      m.accel[i] += accel_bias_[i] + sigma_a * normal_(rng_);
    }
    for (int i = 0; i < 3; ++i) {
      gyro_bias_[i] += walk_g * normal_(rng_);
      accel_bias_[i] += walk_a * normal_(rng_);
    }
  }
  // In the unit the device reports: ImuOptions::AccelerationToMetersPerSecondSquared()
  // turns it back into m/s^2.
  m.accel /= sensor.AccelerationToMetersPerSecondSquared();
  ++index_;
  return m;
}

}  // namespace swarmlio::sim
