// IMU model: ideal specific force and angular rate from a Trajectory, plus
// discrete-time white noise and bias random walks.
//
//   accel = R_W_b^T (a_W - g_W) + b_a + n_a,   g_W = (0, 0, -gravity_m_s2)
//   gyro  = omega_b + b_g + n_g
//   n ~ N(0, density^2 * rate)            (white noise, per sample)
//   b_{k+1} = b_k + N(0, random_walk^2 / rate)   (bias random walk)
// The sensor (rate, densities, random walks, gravity, acceleration unit) is
// the shared swarmlio::ImuOptions, the `imu` section of configs/*.yaml
// (BMI055 defaults); accel is written in g when its acceleration_unit is g.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>

#include "swarmlio/config/option_fields.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

/// A simulated IMU: the shared sensor description (its keys sit directly in
/// the YAML section) plus the simulation-only settings below.
struct SimulatedImuOptions {
  ImuOptions sensor;
  bool noise_enabled = true;                      // white noise and biases
  double gyro_bias_initial_sigma_rad_s = 5.0e-3;  // 1-sigma of the initial gyro bias
  double accel_bias_initial_sigma_m_s2 = 5.0e-2;  // 1-sigma of the initial accel bias
  double time_offset_s = 0.0;  // IMU stamps minus LiDAR stamps of the same instant [s]

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

  /// Time of the next sample.
  double next_time() const;
  ImuMeasurement Next();

 private:
  SimulatedImuOptions options_;
  const Trajectory* trajectory_;
  double t0_;
  int64_t index_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
  Eigen::Vector3d gyro_bias_;
  Eigen::Vector3d accel_bias_;
};

}  // namespace swarmlio::sim
