// Preprocess: raw LiDAR scan -> filtered, downsampled points in the body frame.
//
// Steps, in this order, for each point of LidarScan::points (LiDAR frame L):
//  1. reject non-finite x, y, z or offset_time_s (NaN / inf);
//  2. Livox tag and line rules (both must pass; FAST-LIO / Swarm-LIO2 write
//     `(line < N && tag == 0x10) || tag == 0x00`, which applies the line rule
//     to 0x10 points only, see field_reference.md 1.8; here they are independent):
//       line rule: keep line < num_lines (num_lines = 0 disables it);
//       tag rule (livox_tag_filter): keep return number (tag bits 5:4) 0 or 1,
//         i.e. the single / first return (tag & 0x30 is 0x00 or 0x10);
//       noise rule (livox_reject_noise): also drop points whose spatial
//         confidence bits (tag bits 1:0) are non-zero (flagged as noise);
//  3. stride: keep every point_stride-th point that passed 1-2 (the 1st,
//     (1+s)th, ...; FAST-LIO point_filter_num);
//  4. range gate in the LiDAR frame: blind_range_m <= |p_L| <= max_range_m;
//  5. transform to the body frame, p_b = R_imu_lidar p_L + p_lidar_in_imu;
//  6. voxel downsampling with leaf voxel_leaf_size_m (VoxelFilter rule: the
//     point nearest each voxel centre is kept with its own time and
//     reflectivity; 0 disables);
//  7. stable sort by time (motion compensation walks the scan in time order).
// Every drop is counted in PreprocessStats.
//
// Sensor presets (PreprocessOptionsFor): blind/max range and line count come
// from LidarOptions; the rest from Swarm-LIO2's shipped configs:
//   | type         | point_stride | voxel_leaf_size_m | livox_tag_filter |
//   | livox_avia   | 4            | 0.2               | true             |
//   | livox_mid360 | 2            | 0.2               | true             |
//   | spinning     | 2            | 0.5               | false            |
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/lio/voxel_filter.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::lio {

struct PreprocessOptions {
  double blind_range_m = 0.5;      // closer points are dropped (FAST-LIO blind) [m]
  double max_range_m = 450.0;      // farther points are dropped [m]
  int point_stride = 4;            // keep every n-th valid point (point_filter_num)
  int num_lines = 6;               // keep line < num_lines; 0 = no line rule (scan_line)
  bool livox_tag_filter = true;    // keep only single / first returns (tag & 0x30 in {0x00, 0x10})
  bool livox_reject_noise = false; // drop points whose tag flags spatial noise (tag & 0x03 != 0)
  double voxel_leaf_size_m = 0.2;  // downsampling voxel (filter_size_surf); 0 = off [m]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("point_stride", point_stride,
      FieldSpec::InRange(1.0, 1000.0, "", "keep every n-th valid point (point_filter_num)"));
    v("voxel_leaf_size_m", voxel_leaf_size_m,
      FieldSpec::InRange(0.0, 100.0, "m", "downsampling voxel (filter_size_surf); 0 = off"));
    config::VisitExperimental(v, [&](auto& x) {
      x("blind_range_m", blind_range_m, FieldSpec::AtLeast(0.0, "m", "closer points are dropped"));
      x("max_range_m", max_range_m, FieldSpec::Positive("m", "farther points are dropped"));
      x("num_lines", num_lines,
        FieldSpec::InRange(0.0, 256.0, "", "keep points with line < num_lines; 0 disables"));
      x("livox_tag_filter", livox_tag_filter,
        FieldSpec::Doc("keep only Livox single / first returns (tag bits 5:4 = 0 or 1)"));
      x("livox_reject_noise", livox_reject_noise,
        FieldSpec::Doc("drop Livox points flagged as spatial noise (tag bits 1:0 != 0)"));
    });
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const;
};

/// Preset for a sensor (see the table above).
PreprocessOptions PreprocessOptionsFor(const LidarOptions& lidar);

/// What happened to the points of the last scan.
struct PreprocessStats {
  int64_t input = 0;
  int64_t non_finite = 0;     // NaN / inf coordinate or time
  int64_t tag_rejected = 0;   // Livox tag rule (return number or noise flag)
  int64_t line_rejected = 0;  // line >= num_lines
  int64_t stride_skipped = 0;
  int64_t blind = 0;          // closer than blind_range_m
  int64_t too_far = 0;        // farther than max_range_m
  int64_t voxel_merged = 0;   // removed by the voxel filter
  int64_t output = 0;
};

class Preprocess {
 public:
  /// `R_imu_lidar`, `p_lidar_in_imu_m`: the LiDAR extrinsic (LidarOptions).
  /// CHECK-fails on invalid options (validate configs before).
  Preprocess(const PreprocessOptions& options, const Eigen::Matrix3d& R_imu_lidar,
             const Eigen::Vector3d& p_lidar_in_imu_m);

  /// Filters `scan` into `*out` (cleared first), body frame, sorted by time.
  void Run(const LidarScan& scan, std::vector<PointXYZT>* out, PreprocessStats* stats = nullptr);

  const PreprocessOptions& options() const { return options_; }

 private:
  PreprocessOptions options_;
  Eigen::Matrix3d R_imu_lidar_;
  Eigen::Vector3d p_lidar_in_imu_m_;
  VoxelFilter voxel_filter_;
  std::vector<PointXYZT> kept_;  // scratch: points before downsampling
};

}  // namespace swarmlio::lio
