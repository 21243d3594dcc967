// LidarOptions: what the LiDAR is and how it is mounted (YAML section `lidar`).
//
// Defaults describe a Livox Avia with an identity extrinsic; the presets in
// configs/ set the mounting of a real platform. Every key, its unit, default
// and source is listed in docs/configuration.md.
//
// Extrinsic convention (same as FAST-LIO's extrinsic_R / extrinsic_T and
// Swarm-LIO2's LI_extrinsic_R / LI_extrinsic_T): a point p_L in the LiDAR frame
// is p_I = R_imu_lidar * p_L + p_lidar_in_imu_m in the IMU (body) frame, i.e.
// p_lidar_in_imu_m is the LiDAR origin expressed in the IMU frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sensors/lidar_formats.h"

namespace swarmlio {

enum class LidarType { kLivoxAvia, kLivoxMid360, kSpinning };

}  // namespace swarmlio

namespace swarmlio::config {

template <>
struct EnumTraits<LidarType> {
  static constexpr std::array<std::pair<LidarType, const char*>, 3> kNames{{
      {LidarType::kLivoxAvia, "livox_avia"},
      {LidarType::kLivoxMid360, "livox_mid360"},
      {LidarType::kSpinning, "spinning"},
  }};
};

}  // namespace swarmlio::config

namespace swarmlio {

struct LidarOptions {
  LidarType type = LidarType::kLivoxAvia;
  LidarMessageFormat message_format = LidarMessageFormat::kLivoxCustomMsg;
  double scan_rate_hz = 10.0;           // frames per second [Hz]
  double fov_horizontal_deg = 70.4;     // [deg]
  double fov_vertical_min_deg = -38.6;  // lowest beam elevation [deg]
  double fov_vertical_max_deg = 38.6;   // highest beam elevation [deg]
  int points_per_second = 240000;       // first-return point rate [1/s]
  int num_lines = 6;                    // scan_line: lasers / rings
  double blind_range_m = 0.5;           // closer points are dropped [m]
  double max_range_m = 450.0;           // farther points are dropped [m]
  double range_noise_stddev_m = 0.02;   // 1-sigma range error [m]
  double angular_precision_deg = 0.0;   // 1-sigma beam direction error (datasheet); 0 = unknown [deg]
  TimestampUnit timestamp_unit = TimestampUnit::kNanosecond;
  Eigen::Matrix3d R_imu_lidar = Eigen::Matrix3d::Identity();   // rotation LiDAR -> IMU
  Eigen::Vector3d p_lidar_in_imu_m = Eigen::Vector3d::Zero();  // LiDAR origin in IMU frame [m]
  // 1-sigma per axis of the calibration above as its user knows it (a good
  // LiDAR-IMU calibration: a few tenths of a degree, a few millimetres). Not
  // used to correct anything: the first scan anchors the map through the
  // calibration, so its error moves the whole map, and the position
  // covariance in G carries it (lio/calibration_gauge.h).
  double calibration_rotation_sigma_deg = 0.2;  // [deg]
  double calibration_translation_sigma_m = 0.005;  // [m]

  /// Largest tolerated max |R^T R - I| of R_imu_lidar (4-digit calibrations pass).
  static constexpr double kRotationTolerance = 1e-3;

  /// R_imu_lidar projected onto SO(3), for consumers that need an exact rotation.
  Eigen::Quaterniond QuaternionImuLidar() const {
    return Eigen::Quaterniond(R_imu_lidar).normalized();
  }

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("type", type, FieldSpec::Doc("sensor model"));
    v("message_format", message_format, FieldSpec::Doc("ROS message the driver publishes"));
    v("scan_rate_hz", scan_rate_hz, FieldSpec::Positive("Hz", "frames per second").WithMax(200.0));
    v("fov_horizontal_deg", fov_horizontal_deg,
      FieldSpec::Positive("deg", "horizontal field of view").WithMax(360.0));
    v("fov_vertical_min_deg", fov_vertical_min_deg,
      FieldSpec::InRange(-90.0, 90.0, "deg", "lowest beam elevation above the LiDAR x-y plane"));
    v("fov_vertical_max_deg", fov_vertical_max_deg,
      FieldSpec::InRange(-90.0, 90.0, "deg", "highest beam elevation above the LiDAR x-y plane"));
    v("points_per_second", points_per_second,
      FieldSpec::InRange(1.0, 1e8, "1/s", "first-return point rate"));
    v("num_lines", num_lines,
      FieldSpec::InRange(1.0, 256.0, "", "lasers / rings (FAST-LIO scan_line)"));
    v("blind_range_m", blind_range_m, FieldSpec::AtLeast(0.0, "m", "points closer are dropped"));
    v("max_range_m", max_range_m, FieldSpec::Positive("m", "points farther are dropped"));
    v("range_noise_stddev_m", range_noise_stddev_m,
      FieldSpec::InRange(0.0, 1.0, "m", "1-sigma range noise (sensor model and simulator)"));
    v("angular_precision_deg", angular_precision_deg,
      FieldSpec::InRange(0.0, 5.0, "deg",
                         "1-sigma beam direction error from the datasheet (estimator's noisy-plane "
                         "rule); 0 = unknown"));
    v("timestamp_unit", timestamp_unit, FieldSpec::Doc("unit of the per-point time field"));
    v("R_imu_lidar", R_imu_lidar,
      FieldSpec::InRange(-1.0, 1.0, "", "rotation LiDAR -> IMU (FAST-LIO extrinsic_R)"));
    v("p_lidar_in_imu_m", p_lidar_in_imu_m,
      FieldSpec::InRange(-10.0, 10.0, "m", "LiDAR origin in the IMU frame (FAST-LIO extrinsic_T)"));
    v("calibration_rotation_sigma_deg", calibration_rotation_sigma_deg,
      FieldSpec::InRange(0.0, 10.0, "deg", "1-sigma per axis of R_imu_lidar (its calibration)"));
    v("calibration_translation_sigma_m", calibration_translation_sigma_m,
      FieldSpec::InRange(0.0, 1.0, "m", "1-sigma per axis of p_lidar_in_imu_m (its calibration)"));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const {
    std::string error = config::ValidateFields(*this);
    if (!error.empty()) return error;
    std::ostringstream os;
    if (!(fov_vertical_min_deg < fov_vertical_max_deg)) {
      os << "fov_vertical_min_deg: must be below fov_vertical_max_deg (" << fov_vertical_min_deg
         << " >= " << fov_vertical_max_deg << ")";
    } else if (!(blind_range_m < max_range_m)) {
      os << "blind_range_m: must be below max_range_m (" << blind_range_m << " >= " << max_range_m
         << ")";
    } else if (message_format == LidarMessageFormat::kLivoxCustomMsg &&
               type == LidarType::kSpinning) {
      os << "message_format: livox_custom_msg needs a Livox type, not spinning (use pointcloud2)";
    } else if (message_format == LidarMessageFormat::kLivoxCustomMsg &&
               timestamp_unit != TimestampUnit::kNanosecond) {
      os << "timestamp_unit: must be ns for livox_custom_msg (its offset_time is in ns)";
    } else {
      const Eigen::Matrix3d gram_error =
          R_imu_lidar.transpose() * R_imu_lidar - Eigen::Matrix3d::Identity();
      const double orthonormality_error = gram_error.cwiseAbs().maxCoeff();
      if (!(orthonormality_error <= kRotationTolerance) || !(R_imu_lidar.determinant() > 0.0)) {
        os << "R_imu_lidar: not a rotation matrix (max |R^T R - I| = " << orthonormality_error
           << ", det = " << R_imu_lidar.determinant() << "; need <= " << kRotationTolerance
           << " and det > 0)";
      }
    }
    return os.str();
  }
};

}  // namespace swarmlio
