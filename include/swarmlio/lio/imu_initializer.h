// IMU initialization from a static start (docs/imu.md, "Initialization").
//
// The initializer keeps a sliding window of the latest IMU samples (a sample
// count, default 200 = FAST-LIO's MAX_INI_COUNT, or a duration) and, when
// asked, estimates from the window mean:
//   - the global frame G := the IMU frame at the last sample of the window, so
//     R_G_b = I and p_b_in_G = v_b_in_G = 0;
//   - gyro bias b_g = mean angular rate [rad/s];
//   - gravity g_in_G = -s * k * mean(a_m) [m/s^2], s = acceleration_sign (or,
//     with acceleration_sign 0, detected from the direction of mean(a_m)
//     relative to up_axis: up = +1, down = -1),
//     k = 1 (m/s^2) or nominal_gravity_m_s2 (g units). Its magnitude |g_in_G|
//     is measured, not assumed;
//   - accelerometer bias b_a = 0: it is not observable at a static start (it
//     is indistinguishable from a tilt of gravity), so it gets a prior
//     covariance and gravity the same uncertainty, fully correlated with it
//     (their errors are equal: only g - b_a was measured).
// It refuses (FailedPrecondition, with the measured standard deviations and
// the thresholds) a window that is not static, and rejects NaN samples
// (InvalidArgument).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

/// Acceleration unit as configured for initialization: a fixed unit, or
/// detected from |mean a_m| at the static start (~1 -> g, ~9.8 -> m/s^2).
enum class AccelerationUnitSetting { kMetersPerSecondSquared, kStandardGravity, kAuto };

/// The IMU axis that points (roughly) up at the static start, in the IMU
/// frame: the reference for telling a normal accelerometer (specific force
/// up) from a sign-flipped driver (down). kNone: no reference.
enum class ImuUpAxis { kNone, kPlusX, kMinusX, kPlusY, kMinusY, kPlusZ, kMinusZ };

/// Direction of the reported mean acceleration at rest, relative to up_axis.
enum class SpecificForceDirection {
  kUp,            // within max_up_axis_angle_deg of up_axis: normal (specific force)
  kDown,          // within that angle of -up_axis: sign-flipped driver (or upside down)
  kUndetermined,  // neither (tilted mount), or up_axis none
};

/// Unit vector of `axis` (zero for kNone).
Eigen::Vector3d UpAxisVector(ImuUpAxis axis);

}  // namespace swarmlio::lio

namespace swarmlio::config {

template <>
struct EnumTraits<lio::AccelerationUnitSetting> {
  static constexpr std::array<std::pair<lio::AccelerationUnitSetting, const char*>, 3> kNames{{
      {lio::AccelerationUnitSetting::kMetersPerSecondSquared, "m_s2"},
      {lio::AccelerationUnitSetting::kStandardGravity, "g"},
      {lio::AccelerationUnitSetting::kAuto, "auto"},
  }};
};

template <>
struct EnumTraits<lio::ImuUpAxis> {
  static constexpr std::array<std::pair<lio::ImuUpAxis, const char*>, 7> kNames{{
      {lio::ImuUpAxis::kNone, "none"},
      {lio::ImuUpAxis::kPlusX, "+x"},
      {lio::ImuUpAxis::kMinusX, "-x"},
      {lio::ImuUpAxis::kPlusY, "+y"},
      {lio::ImuUpAxis::kMinusY, "-y"},
      {lio::ImuUpAxis::kPlusZ, "+z"},
      {lio::ImuUpAxis::kMinusZ, "-z"},
  }};
};

template <>
struct EnumTraits<lio::SpecificForceDirection> {
  static constexpr std::array<std::pair<lio::SpecificForceDirection, const char*>, 3> kNames{{
      {lio::SpecificForceDirection::kUp, "up"},
      {lio::SpecificForceDirection::kDown, "down"},
      {lio::SpecificForceDirection::kUndetermined, "undetermined"},
  }};
};

}  // namespace swarmlio::config

namespace swarmlio::lio {

struct ImuInitializerOptions {
  // Samples averaged (FAST-LIO MAX_INI_COUNT); used when window_duration_s == 0.
  int window_num_samples = 200;
  double window_duration_s = 0.0;  // > 0: average over this duration instead [s]
  AccelerationUnitSetting acceleration_unit = AccelerationUnitSetting::kAuto;
  // +1: device reports specific force (a - g); -1: it reports -(a - g); 0: auto, from the
  // direction of the mean acceleration at rest relative to up_axis (+1 when undetermined).
  int acceleration_sign = 1;
  ImuUpAxis up_axis = ImuUpAxis::kPlusZ;  // IMU axis pointing up at rest (REP 103: +z)
  double max_up_axis_angle_deg = 60.0;    // tilt of up_axis from vertical still judged [deg]
  // Converts g units to m/s^2; reference of the magnitude check [m/s^2].
  double nominal_gravity_m_s2 = 9.81;
  double max_gravity_error_ratio = 0.1;  // | |g| / nominal - 1 | allowed after unit conversion
  double max_gyro_stddev_rad_s = 0.05;   // static test: sqrt(trace Cov(w_m)) [rad/s]
  double max_accel_stddev_m_s2 = 0.3;    // static test: sqrt(trace Cov(a_m)) [m/s^2]
  double max_gyro_bias_rad_s = 0.2;      // |mean w_m| above this = not static (steady turn) [rad/s]
  // Initial covariance (1-sigma, per axis). G is defined by the initial pose,
  // so pose and velocity are known up to the conditioning floors below.
  double initial_rotation_stddev_rad = 1e-3;    // [rad]
  double initial_position_stddev_m = 1e-3;      // [m]
  double initial_velocity_stddev_m_s = 1e-2;    // static start [m/s]
  double gyro_bias_stddev_floor_rad_s = 1e-3;   // added to the standard error of the mean [rad/s]
  double initial_accel_bias_stddev_m_s2 = 0.1;  // prior on the unobservable b_a [m/s^2]
  double gravity_stddev_floor_m_s2 = 1e-3;      // added to the acc-mean standard error [m/s^2]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("window_num_samples", window_num_samples,
      FieldSpec::InRange(2.0, 1e6, "", "samples averaged (when window_duration_s is 0)"));
    v("window_duration_s", window_duration_s,
      FieldSpec::InRange(0.0, 60.0, "s", "duration averaged instead of a count (0 = use count)"));
    v("acceleration_unit", acceleration_unit,
      FieldSpec::Doc("unit of the reported acceleration: m_s2, g or auto (detected at rest)"));
    v("acceleration_sign", acceleration_sign,
      FieldSpec::InRange(-1.0, 1.0, "",
                         "+1: specific force (a - g); -1: device reports -(a - g); 0: auto "
                         "(from the static start and up_axis)"));
    v("up_axis", up_axis,
      FieldSpec::Doc("IMU axis that points up at the static start (+x, -x, +y, -y, +z, -z, "
                     "none): tells a normal accelerometer from a sign-flipped one"));
    v("max_up_axis_angle_deg", max_up_axis_angle_deg,
      FieldSpec::InRange(1.0, 89.0, "deg",
                         "largest angle between the mean acceleration at rest and +-up_axis "
                         "for which the direction counts as up or down"));
    v("nominal_gravity_m_s2", nominal_gravity_m_s2,
      FieldSpec::InRange(9.7, 9.9, "m/s^2", "g-unit conversion and magnitude-check reference"));
    v("max_gravity_error_ratio", max_gravity_error_ratio,
      FieldSpec::InRange(0.0, 0.5, "", "allowed relative error of the measured |g|"));
    v("max_gyro_stddev_rad_s", max_gyro_stddev_rad_s,
      FieldSpec::Positive("rad/s", "static test: gyro standard deviation"));
    v("max_accel_stddev_m_s2", max_accel_stddev_m_s2,
      FieldSpec::Positive("m/s^2", "static test: accelerometer standard deviation"));
    v("max_gyro_bias_rad_s", max_gyro_bias_rad_s,
      FieldSpec::Positive("rad/s", "static test: largest plausible gyro bias"));
    v("initial_rotation_stddev_rad", initial_rotation_stddev_rad,
      FieldSpec::Positive("rad", "initial attitude 1-sigma"));
    v("initial_position_stddev_m", initial_position_stddev_m,
      FieldSpec::Positive("m", "initial position 1-sigma"));
    v("initial_velocity_stddev_m_s", initial_velocity_stddev_m_s,
      FieldSpec::Positive("m/s", "initial velocity 1-sigma"));
    v("gyro_bias_stddev_floor_rad_s", gyro_bias_stddev_floor_rad_s,
      FieldSpec::Positive("rad/s", "floor added to the gyro-bias standard error"));
    v("initial_accel_bias_stddev_m_s2", initial_accel_bias_stddev_m_s2,
      FieldSpec::Positive("m/s^2", "prior 1-sigma of the unobservable accelerometer bias"));
    v("gravity_stddev_floor_m_s2", gravity_stddev_floor_m_s2,
      FieldSpec::Positive("m/s^2", "floor added to the gravity standard error"));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const;
};

/// Result of a successful initialization.
struct ImuInitialization {
  int64_t stamp_ns = 0;   // time of the state: the last sample of the window
  // Sensor time at which the odometry started (its first outputs): stamp_ns
  // at rest; in flight, the newest input when its last pass ended.
  int64_t started_ns = 0;
  ImuSample last_sample;  // that sample, raw (the propagator's first input)
  EgoState state;         // R_G_b = I, p = v = 0, b_g, b_a = 0, g_in_G
  Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim> covariance =
      Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim>::Zero();
  AccelerationUnit acceleration_unit =
      AccelerationUnit::kMetersPerSecondSquared;  // used / detected
  bool unit_detected = false;                     // true when acceleration_unit came from "auto"
  double acceleration_to_m_s2 = 1.0;              // signed factor: a [m/s^2] = factor * reported a
  double gravity_magnitude_m_s2 = 0.0;            // |g_in_G| as measured
  int num_samples = 0;
  double gyro_stddev_rad_s = 0.0;  // sqrt(trace Cov(w_m)) over the window
  double accel_stddev_m_s2 = 0.0;  // sqrt(trace Cov(a_m)) over the window, in m/s^2
  // Accelerometer sign: the reported mean acceleration at rest points up
  // (normal) or down (sign-flipped driver) relative to the options' up_axis.
  SpecificForceDirection reported_direction = SpecificForceDirection::kUndetermined;
  double angle_to_up_axis_deg = 0.0;  // angle between the reported mean acc and up_axis
  int acceleration_sign = 1;          // used: configured, or detected (acceleration_sign: 0)
  bool sign_detected = false;         // true when acceleration_sign came from auto (0)
  /// Non-empty when the data contradict the configured sign (or auto could
  /// not decide): what was seen and the option to set. The caller shows it.
  std::string sign_warning;
  // In-flight initialization (lio::Odometry with initialization: in_flight):
  bool in_flight = false;         // velocity and gravity from the LiDAR alignment
  int alignment_passes = 0;       // passes over the first scans that were run
  int alignment_num_poses = 0;    // scan poses of the last pass used in the fit
  double alignment_rms_m = 0.0;   // rms position residual of the last fit [m]

  /// One-line human-readable report (the library does not print it).
  std::string Summary() const;
};

class ImuInitializer {
 public:
  /// InvalidArgument when `options` do not validate.
  static Status Create(const ImuInitializerOptions& options,
                       std::unique_ptr<ImuInitializer>* initializer);

  /// Adds a sample to the sliding window. Non-finite values: InvalidArgument
  /// (sample dropped, counted). Stamps not after the previous sample are
  /// skipped and counted (Ok).
  Status AddSample(const ImuSample& sample);

  /// True when the window holds enough samples (or spans the duration).
  bool WindowFull() const;

  /// Estimates the initial state from the current window. FailedPrecondition
  /// when the window is not full, the start is not static, or |g| does not
  /// match the unit; the message names the measured values and thresholds.
  Status Initialize(ImuInitialization* result) const;

  /// In-flight start (docs/imu.md "Initialization in flight"): the same unit
  /// and sign logic on the window, no static test, and a coarse state for the
  /// odometry's alignment passes: R_G_b = I, p = v = 0, b_g = b_a = 0 and
  /// g_in_G = -s k mean(R_G_bk a_m,k) (each sample rotated into G by the
  /// gyro integrated back from the window's end, so a turn does not smear
  /// it), which still contains the mean acceleration of the flight. Only a
  /// unit that makes |g| absurd (beyond +-50 % of nominal) is refused
  /// (FailedPrecondition). The covariance comes from `coarse` (velocity and
  /// gravity sigmas of the coarse guess, gyro-bias prior); the caller refines
  /// velocity and gravity from LiDAR (lio/in_flight_alignment.h).
  struct InFlightCoarseSigmas {
    double velocity_m_s = 2.0;
    double gravity_m_s2 = 2.0;
    double gyro_bias_rad_s = 0.05;
  };
  Status InitializeInFlight(const InFlightCoarseSigmas& coarse, ImuInitialization* result) const;

  /// Empties the window (counters are kept).
  void Reset() { window_.clear(); }

  int num_samples_in_window() const { return static_cast<int>(window_.size()); }
  /// Stamp of the oldest sample in the window (0 when empty) [ns].
  int64_t window_start_ns() const { return window_.empty() ? 0 : window_.front().stamp_ns; }
  int num_rejected_non_finite() const { return num_rejected_non_finite_; }
  int num_skipped_out_of_order() const { return num_skipped_out_of_order_; }

 private:
  explicit ImuInitializer(const ImuInitializerOptions& options) : options_(options) {}
  int64_t DurationNs() const;
  struct UnitAndSign;
  // Steps 1 and 1b of Initialize(): the unit and the sign from the window mean.
  Status DetermineUnitAndSign(const Eigen::Vector3d& mean_accel, UnitAndSign* out) const;
  // The fields both starts share: stamps, unit, sign, |g|, a default state.
  void StartResult(const UnitAndSign& us, double g_norm, ImuInitialization* r) const;
  // The initial covariance of both starts: the options' pose and accel-bias
  // priors, the given velocity sigma and gyro-bias block, and gravity with
  // the b_a prior (fully correlated), what the mean measured, and a floor.
  void SetInitialCovariance(
      double velocity_sigma, const Eigen::Matrix3d& P_gyro_bias,
      const Eigen::Matrix3d& P_gravity_measured, double gravity_sigma_floor,
      Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim>* P) const;

  ImuInitializerOptions options_;
  std::deque<ImuSample> window_;
  int num_rejected_non_finite_ = 0;
  int num_skipped_out_of_order_ = 0;
};

}  // namespace swarmlio::lio
