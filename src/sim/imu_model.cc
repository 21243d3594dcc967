#include "swarmlio/sim/imu_model.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"
#include "swarmlio/sim/random.h"

namespace swarmlio::sim {
namespace {

// Sub-streams of an ImuModel's seed (the base stream, white noise and biases,
// is the seed itself, as it always was).
constexpr uint64_t kSampleStream = 1;  // dropouts, stamp jitter
constexpr uint64_t kErrorStream = 2;   // per-drone constants (ImuErrors)

Eigen::Vector3d Vibration(const Eigen::Vector3d& amplitude,
                          const Eigen::Vector3d& phase,
                          const Eigen::Vector3d& harmonic_amplitude,
                          const Eigen::Vector3d& harmonic_phase,
                          double omega,
                          int harmonic,
                          double t) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    v[i] = amplitude[i] * std::sin(omega * t + phase[i]) +
           harmonic_amplitude[i] * std::sin(harmonic * omega * t + harmonic_phase[i]);
  }
  return v;
}

double Quantize(double value, double lsb) { return lsb * std::round(value / lsb); }

}  // namespace

bool ImuImperfectionOptions::HasVibration() const {
  return !accel_vibration_m_s2.isZero(0.0) || !accel_vibration_harmonic_m_s2.isZero(0.0) ||
         !gyro_vibration_rad_s.isZero(0.0) || !gyro_vibration_harmonic_rad_s.isZero(0.0);
}

bool ImuImperfectionOptions::HasScaleOrMisalignment() const {
  return gyro_scale_factor_sigma > 0.0 || gyro_misalignment_sigma_rad > 0.0 ||
         accel_scale_factor_sigma > 0.0 || accel_misalignment_sigma_rad > 0.0;
}

void IdealImu(const Trajectory& trajectory, double t, double gravity_m_s2,
              Eigen::Vector3d* omega_b, Eigen::Vector3d* specific_force_b) {
  const KinematicState s = trajectory.StateAt(t);
  *omega_b = s.omega_b;
  *specific_force_b = s.R_W_b.transpose() * (s.a_b_in_W + Eigen::Vector3d(0, 0, gravity_m_s2));
}

ImuErrors ImuModel::DrawErrors(const SimulatedImuOptions& options, uint64_t seed) {
  const ImuImperfectionOptions& o = options.imperfections;
  // A fixed number of draws, whatever is enabled, so that one setting never
  // changes the draws of another.
  std::mt19937_64 rng(DeriveSeed(seed, 0, kErrorStream));
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  auto matrix = [&](double scale_sigma, double misalignment_sigma) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        m(r, c) += (r == c ? scale_sigma : misalignment_sigma) * normal(rng);
      }
    }
    return m;
  };
  auto phases = [&] { return Eigen::Vector3d(phase(rng), phase(rng), phase(rng)); };
  ImuErrors e;
  e.gyro_matrix = matrix(o.gyro_scale_factor_sigma, o.gyro_misalignment_sigma_rad);
  e.accel_matrix = matrix(o.accel_scale_factor_sigma, o.accel_misalignment_sigma_rad);
  e.gyro_phase_rad = phases();
  e.gyro_harmonic_phase_rad = phases();
  e.accel_phase_rad = phases();
  e.accel_harmonic_phase_rad = phases();
  return e;
}

ImuModel::ImuModel(const SimulatedImuOptions& options,
                   const Trajectory* trajectory,
                   double t0_s,
                   uint64_t seed)
    : options_(options),
      trajectory_(trajectory),
      t0_(t0_s),
      rng_(seed),
      sample_rng_(DeriveSeed(seed, 0, kSampleStream)),
      errors_(DrawErrors(options, seed)) {
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
  const ImuImperfectionOptions& imp = options_.imperfections;
  IdealImu(*trajectory_, m.t, sensor.gravity_m_s2, &m.true_gyro, &m.true_accel);
  m.gyro = m.true_gyro;
  m.accel = m.true_accel;
  // Every step below is skipped when off, so that the ideal IMU is unchanged
  // to the last bit.
  if (imp.HasVibration()) {
    const double omega = 2.0 * M_PI * imp.rotor_frequency_hz;
    m.gyro += Vibration(imp.gyro_vibration_rad_s, errors_.gyro_phase_rad,
                        imp.gyro_vibration_harmonic_rad_s, errors_.gyro_harmonic_phase_rad, omega,
                        imp.rotor_harmonic, m.t);
    m.accel += Vibration(imp.accel_vibration_m_s2, errors_.accel_phase_rad,
                         imp.accel_vibration_harmonic_m_s2, errors_.accel_harmonic_phase_rad, omega,
                         imp.rotor_harmonic, m.t);
  }
  if (imp.HasScaleOrMisalignment()) {
    m.gyro = errors_.gyro_matrix * m.gyro;
    m.accel = errors_.accel_matrix * m.accel;
  }
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
  for (int i = 0; i < 3; ++i) {
    if (imp.gyro_lsb_rad_s > 0.0) m.gyro[i] = Quantize(m.gyro[i], imp.gyro_lsb_rad_s);
    if (imp.accel_lsb_m_s2 > 0.0) m.accel[i] = Quantize(m.accel[i], imp.accel_lsb_m_s2);
  }
  if (imp.sample_dropout_probability > 0.0) {
    m.dropped = std::uniform_real_distribution<double>(0.0, 1.0)(sample_rng_) <
                imp.sample_dropout_probability;
  }
  if (imp.timestamp_jitter_s > 0.0) {
    const double limit = 0.25 / sensor.rate_hz;
    m.stamp_jitter_s =
        std::clamp(imp.timestamp_jitter_s * sample_normal_(sample_rng_), -limit, limit);
  }
  // In the unit the device reports: ImuOptions::AccelerationToMetersPerSecondSquared()
  // turns it back into m/s^2.
  m.accel /= sensor.AccelerationToMetersPerSecondSquared();
  ++index_;
  return m;
}

}  // namespace swarmlio::sim
