// Sensor imperfections of the simulator, grouped for a scenario's
// `imperfections:` section (docs/simulator.md, "Imperfections"):
//
//   imperfections: ideal              # or realistic (the default; ideal: every effect off)
//   imperfections:                    # a preset with single values overridden
//     preset: realistic               # the default preset when the key is omitted
//     lidar: {mixed_pixel_probability: 0.2}
//     imu: {timestamp_jitter_s: 0}
//     calibration: {extrinsic_rotation_deg: [0.5, 0.5]}
//     clock: {drift_sigma_ppm: 0}
//
// `lidar` and `imu` are the LidarImperfectionOptions (lidar_options.h) and
// ImuImperfectionOptions (imu_model.h) every drone's sensors start from (a
// drone may override them under its own lidar.imperfections /
// imu.imperfections); the `realistic` LiDAR values depend on the LiDAR type.
// `calibration` is the error of the calibration handed to the estimator
// (swarm.yaml), `clock` the drones' clock drift; both are drawn per drone
// from the scenario seed. The truth is in resolved_scenario.yaml.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sim/imu_model.h"
#include "swarmlio/sim/lidar_options.h"

namespace swarmlio::sim {

enum class ImperfectionPreset { kIdeal, kRealistic };

}  // namespace swarmlio::sim

namespace swarmlio::config {
template <>
struct EnumTraits<sim::ImperfectionPreset> {
  static constexpr std::array<std::pair<sim::ImperfectionPreset, const char*>, 2> kNames{{
      {sim::ImperfectionPreset::kIdeal, "ideal"},
      {sim::ImperfectionPreset::kRealistic, "realistic"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::sim {

/// Error of the calibration the estimator is given. Each magnitude is drawn
/// uniformly from its [min, max] per drone; rotation and translation point in
/// a uniformly random direction, the time error has a random sign.
struct CalibrationErrorOptions {
  std::vector<double> extrinsic_rotation_deg = {0.0, 0.0};   // [min, max] of the angle [deg]
  std::vector<double> extrinsic_translation_m = {0.0, 0.0};  // [min, max] of the length [m]
  std::vector<double> imu_time_offset_s = {0.0, 0.0};        // [min, max] of |error| [s]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("extrinsic_rotation_deg", extrinsic_rotation_deg,
      FieldSpec::InRange(0.0, 10.0, "deg", "[min, max] of the R_imu_lidar error angle"));
    v("extrinsic_translation_m", extrinsic_translation_m,
      FieldSpec::InRange(0.0, 0.5, "m", "[min, max] of the p_lidar_in_imu_m error length"));
    v("imu_time_offset_s", imu_time_offset_s,
      FieldSpec::InRange(0.0, 0.1, "s", "[min, max] of the |IMU time offset error|"));
  }
  std::string Validate() const;
  bool Any() const;
};

/// Per-drone clock drift, on top of each drone's clock_offset_s and
/// clock_drift_ppm: N(0, drift_sigma_ppm) drawn per drone.
struct ClockImperfectionOptions {
  double drift_sigma_ppm = 0.0;  // 1-sigma of the drawn drift [ppm]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("drift_sigma_ppm", drift_sigma_ppm,
      FieldSpec::InRange(0.0, 1000.0, "ppm", "1-sigma of the per-drone clock drift"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// The scenario's `imperfections:` section.
struct ImperfectionOptions {
  ImperfectionPreset preset = ImperfectionPreset::kIdeal;
  LidarImperfectionOptions lidar;
  ImuImperfectionOptions imu;
  CalibrationErrorOptions calibration;
  ClockImperfectionOptions clock;

  /// The values of `preset` for a drone whose LiDAR is of `lidar_type`.
  static ImperfectionOptions ForPreset(ImperfectionPreset preset, LidarType lidar_type);

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("preset", preset, FieldSpec::Doc("values every key below starts from"));
    v("lidar", lidar, FieldSpec::Doc("LiDAR imperfections of every drone"));
    v("imu", imu, FieldSpec::Doc("IMU imperfections of every drone"));
    v("calibration", calibration, FieldSpec::Doc("error of the calibration in swarm.yaml"));
    v("clock", clock, FieldSpec::Doc("per-drone clock drift"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// `realistic` values (docs/simulator.md has the table and the sources).
LidarImperfectionOptions RealisticLidarImperfections(LidarType type);
ImuImperfectionOptions RealisticImuImperfections();
CalibrationErrorOptions RealisticCalibrationError();
ClockImperfectionOptions RealisticClock();

/// One drone's calibration error: given = truth (+) error.
struct CalibrationError {
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();   // R_given = R_true Exp(this)
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  // p_given = p_true + this
  double imu_time_offset_s = 0.0;                           // offset_given = offset_true + this
};

/// LiDAR-IMU calibration: the extrinsic and the IMU time offset (IMU stamps
/// minus LiDAR stamps of the same instant).
struct SensorCalibration {
  Eigen::Matrix3d R_imu_lidar = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_lidar_in_imu_m = Eigen::Vector3d::Zero();
  double imu_time_offset_s = 0.0;
};

/// Draws a calibration error from `seed` (a fixed number of draws).
CalibrationError DrawCalibrationError(const CalibrationErrorOptions& options, uint64_t seed);
/// `truth` with `error` applied.
SensorCalibration ApplyCalibrationError(const SensorCalibration& truth,
                                        const CalibrationError& error);
/// Draws a clock drift [ppm] from `seed`.
double DrawClockDriftPpm(const ClockImperfectionOptions& options, uint64_t seed);

}  // namespace swarmlio::sim
