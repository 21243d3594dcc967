// ImuOptions: the IMU's rate, units and noise (YAML section `imu`).
//
// Noise densities default to a Bosch BMI055 (the IMU of the Pixhawk flight
// controllers in the Swarm-LIO paper, Sec. IV): gyro 0.014 deg/s/sqrt(Hz),
// accelerometer 150 ug/sqrt(Hz). Datasheets give no bias random walk; the
// defaults are typical of consumer MEMS and should be identified (Allan
// variance) for real hardware. These describe the sensor; the estimator's
// process-noise tuning is a separate, estimator-owned option.
// See docs/configuration.md.
#pragma once

#include <array>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"

namespace swarmlio {

/// Unit of ImuSample::linear_acceleration as the device reports it.
enum class AccelerationUnit {
  kMetersPerSecondSquared,  // "m_s2": sensor_msgs/Imu convention (e.g. MAVROS)
  kStandardGravity,         // "g": Livox built-in IMUs (/livox/imu)
};

}  // namespace swarmlio

namespace swarmlio::config {

template <>
struct EnumTraits<AccelerationUnit> {
  static constexpr std::array<std::pair<AccelerationUnit, const char*>, 2> kNames{{
      {AccelerationUnit::kMetersPerSecondSquared, "m_s2"},
      {AccelerationUnit::kStandardGravity, "g"},
  }};
};

}  // namespace swarmlio::config

namespace swarmlio {

struct ImuOptions {
  double rate_hz = 200.0;  // [Hz]
  AccelerationUnit acceleration_unit = AccelerationUnit::kMetersPerSecondSquared;
  double gyro_noise_density_rad_s_sqrt_hz = 2.443e-4;    // 0.014 deg/s/sqrt(Hz)
  double accel_noise_density_m_s2_sqrt_hz = 1.471e-3;    // 150 ug/sqrt(Hz)
  double gyro_bias_random_walk_rad_s2_sqrt_hz = 2.0e-5;  // [rad/s^2/sqrt(Hz)]
  double accel_bias_random_walk_m_s3_sqrt_hz = 3.0e-4;   // [m/s^3/sqrt(Hz)]
  double gravity_m_s2 = 9.81;                            // local gravity magnitude [m/s^2]

  /// Factor that turns a reported acceleration into m/s^2 (gravity_m_s2 for
  /// "g", so that data the simulator writes in g converts back exactly).
  double AccelerationToMetersPerSecondSquared() const {
    return acceleration_unit == AccelerationUnit::kStandardGravity ? gravity_m_s2 : 1.0;
  }

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("rate_hz", rate_hz, FieldSpec::Positive("Hz", "sample rate").WithMax(10000.0));
    v("acceleration_unit", acceleration_unit,
      FieldSpec::Doc("unit of the reported linear acceleration"));
    v("gyro_noise_density_rad_s_sqrt_hz", gyro_noise_density_rad_s_sqrt_hz,
      FieldSpec::InRange(0.0, 0.1, "rad/s/sqrt(Hz)", "gyroscope white noise density"));
    v("accel_noise_density_m_s2_sqrt_hz", accel_noise_density_m_s2_sqrt_hz,
      FieldSpec::InRange(0.0, 1.0, "m/s^2/sqrt(Hz)", "accelerometer white noise density"));
    v("gyro_bias_random_walk_rad_s2_sqrt_hz", gyro_bias_random_walk_rad_s2_sqrt_hz,
      FieldSpec::InRange(0.0, 0.1, "rad/s^2/sqrt(Hz)", "gyroscope bias random walk"));
    v("accel_bias_random_walk_m_s3_sqrt_hz", accel_bias_random_walk_m_s3_sqrt_hz,
      FieldSpec::InRange(0.0, 1.0, "m/s^3/sqrt(Hz)", "accelerometer bias random walk"));
    v("gravity_m_s2", gravity_m_s2,
      FieldSpec::InRange(9.7, 9.9, "m/s^2", "gravity magnitude (simulator, g conversion)"));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

}  // namespace swarmlio
