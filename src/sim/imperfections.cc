// The `realistic` preset. Sources and reasoning: docs/simulator.md,
// "Imperfections" (the table there lists every value below).
#include "swarmlio/sim/imperfections.h"

#include <cmath>
#include <random>

#include "swarmlio/math/angles.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::sim {
namespace {

// "" when `range` is [min, max] with min <= max, else "key: reason".
std::string CheckInterval(const char* key, const std::vector<double>& range) {
  if (range.size() != 2) return std::string(key) + ": expected [min, max]";
  if (!(range[0] <= range[1])) return std::string(key) + ": min must not exceed max";
  return {};
}

}  // namespace

std::string CalibrationErrorOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (error.empty()) error = CheckInterval("extrinsic_rotation_deg", extrinsic_rotation_deg);
  if (error.empty()) error = CheckInterval("extrinsic_translation_m", extrinsic_translation_m);
  if (error.empty()) error = CheckInterval("imu_time_offset_s", imu_time_offset_s);
  return error;
}

bool CalibrationErrorOptions::Any() const {
  for (const std::vector<double>* r :
       {&extrinsic_rotation_deg, &extrinsic_translation_m, &imu_time_offset_s}) {
    for (double x : *r) {
      if (x != 0.0) return true;
    }
  }
  return false;
}

LidarImperfectionOptions RealisticLidarImperfections(LidarType type) {
  LidarImperfectionOptions o;
  if (type == LidarType::kLivoxAvia) {
    o.angular_noise_deg = 0.05;               // Avia: angular random error < 0.05 deg (1 sigma)
    o.beam_divergence_horizontal_deg = 0.03;  // Avia: 0.03 (H) x 0.28 (V) deg
    o.beam_divergence_vertical_deg = 0.28;
  } else {                                    // Mid-360 (spinning: the same, as a generic sensor)
    o.angular_noise_deg = 0.15;               // Mid-360: angular precision < 0.15 deg (1 sigma)
    o.beam_divergence_horizontal_deg = 0.18;  // Mid-360: 0.18 deg
    o.beam_divergence_vertical_deg = 0.18;
  }
  o.range_noise_per_m = 5e-4;  // 2 cm at short range -> 2.06 cm at 10 m, 2.8 cm at 40 m
  o.incidence_noise = true;
  o.mixed_pixel_probability = 0.5;
  o.edge_min_separation_m = 0.1;
  o.multi_return = false;  // Livox default: single (first) return
  o.low_reflectivity_bias_m = 0.03;
  o.low_reflectivity_threshold = 20.0;
  o.range_dropout_at_max_range = 0.5;
  o.range_dropout_exponent = 2.0;
  return o;
}

ImuImperfectionOptions RealisticImuImperfections() {
  ImuImperfectionOptions o;
  o.rotor_frequency_hz = 180.0;  // ~10800 rpm: a 1-1.5 kg quadrotor with 5-7" props in hover
  o.rotor_harmonic = 2;
  o.accel_vibration_m_s2 = Eigen::Vector3d(0.15, 0.15, 0.3);
  o.accel_vibration_harmonic_m_s2 = Eigen::Vector3d(0.05, 0.05, 0.1);
  o.gyro_vibration_rad_s = Eigen::Vector3d(0.01, 0.01, 0.005);
  o.gyro_vibration_harmonic_rad_s = Eigen::Vector3d(0.003, 0.003, 0.002);
  o.gyro_scale_factor_sigma = 0.005;  // ICM-40609-D / BMI088: sensitivity error +-0.5 %
  o.accel_scale_factor_sigma = 0.005;
  o.gyro_misalignment_sigma_rad = 0.005;  // cross-axis sensitivity +-1 % as 2 sigma
  o.accel_misalignment_sigma_rad = 0.005;
  o.gyro_lsb_rad_s = 2000.0 / 32768.0 * kRadiansPerDegree;  // +-2000 deg/s over 16 bit
  o.accel_lsb_m_s2 = 24.0 * 9.80665 / 32768.0;  // BMI088 +-24 g over 16 bit
  o.sample_dropout_probability = 1e-3;
  o.timestamp_jitter_s = 1e-4;
  return o;
}

CalibrationErrorOptions RealisticCalibrationError() {
  CalibrationErrorOptions o;
  o.extrinsic_rotation_deg = {0.2, 0.5};
  o.extrinsic_translation_m = {0.005, 0.010};
  o.imu_time_offset_s = {0.0005, 0.0015};
  return o;
}

ClockImperfectionOptions RealisticClock() {
  ClockImperfectionOptions o;
  o.drift_sigma_ppm = 10.0;  // free-running crystal, +-20 ppm tolerance as 2 sigma
  return o;
}

ImperfectionOptions ImperfectionOptions::ForPreset(ImperfectionPreset preset,
                                                   LidarType lidar_type) {
  ImperfectionOptions o;
  o.preset = preset;
  if (preset == ImperfectionPreset::kRealistic) {
    o.lidar = RealisticLidarImperfections(lidar_type);
    o.imu = RealisticImuImperfections();
    o.calibration = RealisticCalibrationError();
    o.clock = RealisticClock();
  }
  return o;
}

CalibrationError DrawCalibrationError(const CalibrationErrorOptions& options, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal;
  auto magnitude = [&](const std::vector<double>& range) {
    const double u = uniform(rng);
    return range.size() == 2 ? range[0] + u * (range[1] - range[0]) : 0.0;
  };
  auto direction = [&] {
    Eigen::Vector3d d;
    do {
      d = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    } while (d.squaredNorm() < 1e-12);
    return d.normalized();
  };
  CalibrationError e;
  const double angle = magnitude(options.extrinsic_rotation_deg) * kRadiansPerDegree;
  e.rotation_rad = angle * direction();
  const double length = magnitude(options.extrinsic_translation_m);
  e.translation_m = length * direction();
  const double time = magnitude(options.imu_time_offset_s);
  e.imu_time_offset_s = uniform(rng) < 0.5 ? -time : time;
  return e;
}

SensorCalibration ApplyCalibrationError(const SensorCalibration& truth,
                                        const CalibrationError& error) {
  SensorCalibration given = truth;
  if (!error.rotation_rad.isZero(0.0)) {
    given.R_imu_lidar = truth.R_imu_lidar * so3::Exp(error.rotation_rad);
  }
  given.p_lidar_in_imu_m = truth.p_lidar_in_imu_m + error.translation_m;
  given.imu_time_offset_s = truth.imu_time_offset_s + error.imu_time_offset_s;
  return given;
}

double DrawClockDriftPpm(const ClockImperfectionOptions& options, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  return options.drift_sigma_ppm * normal(rng);
}

}  // namespace swarmlio::sim
