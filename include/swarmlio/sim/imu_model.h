// IMU model: ideal specific force and angular rate from a Trajectory, plus
// discrete-time white noise and bias random walks, and (off by default) the
// imperfections of a real IMU on a flying drone.
//
//   accel = Q_a( M_a (f_b + v_a(t)) + b_a + n_a ),   f_b = R_W_b^T (a_W - g_W)
//   gyro  = Q_g( M_g (w_b + v_g(t)) + b_g + n_g ),   g_W = (0, 0, -gravity_m_s2)
//   n ~ N(0, density^2 * rate)            (white noise, per sample)
//   b_{k+1} = b_k + N(0, random_walk^2 / rate)   (bias random walk)
//   v(t) = A1 sin(2 pi f t + phi1) + A2 sin(2 pi h f t + phi2)  per axis
//          (rotor vibration at f = rotor_frequency_hz and its harmonic h,
//          amplitudes as seen at the output, aliased by the sample rate)
//   M = I + diag(scale errors) + off-diagonal misalignment (per drone)
//   Q(x) = lsb * round(x / lsb)           (quantisation; none when lsb = 0)
// A sample may be lost (dropout) and its stamp may carry jitter. The sensor
// (rate, densities, random walks, gravity, acceleration unit) is the shared
// swarmlio::ImuOptions, the `imu` section of configs/*.yaml (BMI055
// defaults); accel is written in g when its acceleration_unit is g.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

/// IMU imperfections (docs/simulator.md, "Imperfections"). Every default is
/// off: the `ideal` preset; RealisticImuImperfections() (imperfections.h)
/// gives the `realistic` values. With all of them off an IMU produces the same
/// samples as before they existed.
struct ImuImperfectionOptions {
  double rotor_frequency_hz = 180.0;  // vibration fundamental (rotor speed) [Hz]
  int rotor_harmonic = 2;             // the second line is at this multiple of it
  Eigen::Vector3d accel_vibration_m_s2 = Eigen::Vector3d::Zero();           // amplitude per axis
  Eigen::Vector3d accel_vibration_harmonic_m_s2 = Eigen::Vector3d::Zero();  // [m/s^2]
  Eigen::Vector3d gyro_vibration_rad_s = Eigen::Vector3d::Zero();           // amplitude per axis
  Eigen::Vector3d gyro_vibration_harmonic_rad_s = Eigen::Vector3d::Zero();  // [rad/s]
  double gyro_scale_factor_sigma = 0.0;      // 1-sigma per-axis scale error (fraction)
  double gyro_misalignment_sigma_rad = 0.0;  // 1-sigma per off-diagonal element [rad]
  double accel_scale_factor_sigma = 0.0;
  double accel_misalignment_sigma_rad = 0.0;
  double gyro_lsb_rad_s = 0.0;              // quantisation step; 0 = none [rad/s]
  double accel_lsb_m_s2 = 0.0;              // quantisation step; 0 = none [m/s^2]
  double sample_dropout_probability = 0.0;  // a sample is lost
  double timestamp_jitter_s = 0.0;          // 1-sigma stamp jitter, clamped to +-0.25 / rate_hz [s]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("rotor_frequency_hz", rotor_frequency_hz,
      FieldSpec::Positive("Hz", "vibration fundamental (rotor speed)").WithMax(1e4));
    v("rotor_harmonic", rotor_harmonic,
      FieldSpec::InRange(2, 10, "", "multiple of rotor_frequency_hz of the second vibration line"));
    v("accel_vibration_m_s2", accel_vibration_m_s2,
      FieldSpec::InRange(0.0, 50.0, "m/s^2", "accelerometer vibration amplitude per axis"));
    v("accel_vibration_harmonic_m_s2", accel_vibration_harmonic_m_s2,
      FieldSpec::InRange(0.0, 50.0, "m/s^2", "same at the harmonic"));
    v("gyro_vibration_rad_s", gyro_vibration_rad_s,
      FieldSpec::InRange(0.0, 5.0, "rad/s", "gyroscope vibration amplitude per axis"));
    v("gyro_vibration_harmonic_rad_s", gyro_vibration_harmonic_rad_s,
      FieldSpec::InRange(0.0, 5.0, "rad/s", "same at the harmonic"));
    v("gyro_scale_factor_sigma", gyro_scale_factor_sigma,
      FieldSpec::InRange(0.0, 0.1, "", "1-sigma gyroscope scale-factor error per axis (fraction)"));
    v("gyro_misalignment_sigma_rad", gyro_misalignment_sigma_rad,
      FieldSpec::InRange(0.0, 0.1, "rad", "1-sigma gyroscope axis misalignment / cross-axis"));
    v("accel_scale_factor_sigma", accel_scale_factor_sigma,
      FieldSpec::InRange(0.0, 0.1, "", "1-sigma accelerometer scale-factor error per axis"));
    v("accel_misalignment_sigma_rad", accel_misalignment_sigma_rad,
      FieldSpec::InRange(0.0, 0.1, "rad", "1-sigma accelerometer axis misalignment / cross-axis"));
    v("gyro_lsb_rad_s", gyro_lsb_rad_s,
      FieldSpec::InRange(0.0, 0.1, "rad/s", "gyroscope quantisation step (0 = none)"));
    v("accel_lsb_m_s2", accel_lsb_m_s2,
      FieldSpec::InRange(0.0, 1.0, "m/s^2", "accelerometer quantisation step (0 = none)"));
    v("sample_dropout_probability", sample_dropout_probability,
      FieldSpec::InRange(0.0, 0.5, "", "probability that a sample is lost"));
    v("timestamp_jitter_s", timestamp_jitter_s,
      FieldSpec::InRange(0.0, 0.01, "s", "1-sigma stamp jitter"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
  bool HasVibration() const;
  bool HasScaleOrMisalignment() const;
};

/// The per-drone constants of an IMU's imperfections, drawn from its seed:
/// the matrices M (identity when their sigmas are 0) and the vibration phases.
struct ImuErrors {
  Eigen::Matrix3d gyro_matrix = Eigen::Matrix3d::Identity();  // I + scale + misalignment
  Eigen::Matrix3d accel_matrix = Eigen::Matrix3d::Identity();
  Eigen::Vector3d gyro_phase_rad = Eigen::Vector3d::Zero();  // fundamental, per axis
  Eigen::Vector3d gyro_harmonic_phase_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_phase_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_harmonic_phase_rad = Eigen::Vector3d::Zero();
};

/// A simulated IMU: the shared sensor description (its keys sit directly in
/// the YAML section) plus the simulation-only settings below.
struct SimulatedImuOptions {
  ImuOptions sensor;
  bool noise_enabled = true;                      // white noise and biases
  double gyro_bias_initial_sigma_rad_s = 5.0e-3;  // 1-sigma of the initial gyro bias
  double accel_bias_initial_sigma_m_s2 = 5.0e-2;  // 1-sigma of the initial accel bias
  double time_offset_s = 0.0;  // IMU stamps minus LiDAR stamps of the same instant [s]
  ImuImperfectionOptions imperfections;  // all off by default (the `ideal` preset)

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    sensor.VisitFields(v);
    v("noise_enabled", noise_enabled, FieldSpec::Doc("simulator: add white noise and biases"));
    v("gyro_bias_initial_sigma_rad_s", gyro_bias_initial_sigma_rad_s,
      FieldSpec::AtLeast(0.0, "rad/s", "simulator: 1-sigma of the initial gyro bias"));
    v("accel_bias_initial_sigma_m_s2", accel_bias_initial_sigma_m_s2,
      FieldSpec::AtLeast(0.0, "m/s^2", "simulator: 1-sigma of the initial accelerometer bias"));
    v("time_offset_s", time_offset_s,
      FieldSpec::InRange(-1.0, 1.0, "s", "simulator: IMU stamp delay vs LiDAR stamps"));
    v("imperfections", imperfections,
      FieldSpec::Doc("simulator: IMU imperfections (over the scenario's `imperfections:`)"));
  }
  /// "" when valid, else "key: reason".
  std::string Validate() const {
    std::string error = sensor.Validate();
    return error.empty() ? config::ValidateFields(*this) : error;
  }
};

/// One simulated IMU sample with its ground truth.
struct ImuMeasurement {
  double t = 0.0;                                        // true time [s]
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();        // [rad/s]
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();       // [m/s^2] or [g]
  Eigen::Vector3d true_gyro = Eigen::Vector3d::Zero();   // noise- and bias-free
  Eigen::Vector3d true_accel = Eigen::Vector3d::Zero();  // [m/s^2], always
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   // bias in this sample
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  // [m/s^2]
  bool dropped = false;         // lost on the way (sample dropout): not to be written
  double stamp_jitter_s = 0.0;  // to add to the sample's stamp [s]
};

/// Ideal angular rate [rad/s] and specific force [m/s^2] in the body frame
/// under gravity of magnitude `gravity_m_s2` along -z of W.
void IdealImu(const Trajectory& trajectory,
              double t,
              double gravity_m_s2,
              Eigen::Vector3d* omega_b,
              Eigen::Vector3d* specific_force_b);

/// Generates samples k = 0, 1, ... at t = t0 + k / rate. Not thread-safe;
/// one instance per drone.
class ImuModel {
 public:
  /// `trajectory` must outlive the model.
  ImuModel(const SimulatedImuOptions& options,
           const Trajectory* trajectory,
           double t0_s,
           uint64_t seed);

  /// The per-drone constants a model with these options and this seed uses.
  static ImuErrors DrawErrors(const SimulatedImuOptions& options, uint64_t seed);

  /// Time of the next sample.
  double next_time() const;
  ImuMeasurement Next();
  const ImuErrors& errors() const { return errors_; }

 private:
  SimulatedImuOptions options_;
  const Trajectory* trajectory_;
  double t0_;
  int64_t index_ = 0;
  std::mt19937_64 rng_;         // white noise and biases
  std::mt19937_64 sample_rng_;  // dropouts and stamp jitter
  std::normal_distribution<double> normal_;
  std::normal_distribution<double> sample_normal_;
  Eigen::Vector3d gyro_bias_;
  Eigen::Vector3d accel_bias_;
  ImuErrors errors_;
};

}  // namespace swarmlio::sim
