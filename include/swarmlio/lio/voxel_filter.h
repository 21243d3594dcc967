// VoxelFilter: one representative point per cubic voxel (FAST-LIO's
// filter_size_surf downsampling of the current scan).
//
// Rule: the points are binned into voxels of side leaf_size_m (voxel k covers
// [k * leaf, (k + 1) * leaf) on each axis, see map_voxel_key.h). Each occupied
// voxel keeps the ONE INPUT POINT closest to the voxel centre, unchanged: its
// position, time and reflectivity are a real measurement. A centroid would mix
// the times of points taken up to a scan period apart, which motion
// compensation (per-point time) cannot undo, and would blur reflectivity.
// Ties (equal distance) go to the earlier input point.
//
// Output order: voxels in order of their first input point, so the result is
// a deterministic function of the input sequence. O(n) expected time with a
// tsl::robin_map; the map is kept between calls to avoid reallocation.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::lio {

/// A preprocessed LiDAR point: position in the body (IMU) frame b, its time
/// relative to the scan stamp (the scan start), and its reflectivity.
struct PointXYZT {
  Eigen::Vector3d p_in_b = Eigen::Vector3d::Zero();  // [m]
  double time_s = 0.0;      // offset from the scan stamp (LidarPoint::offset_time_s) [s]
  float reflectivity = 0.f;  // Livox 0-255 scale
};

struct VoxelFilterOptions {
  double leaf_size_m = 0.5;  // voxel side; FAST-LIO filter_size_surf [m]

  template <class V>
  void VisitFields(V&& v) {
    v("leaf_size_m", leaf_size_m,
      config::FieldSpec::Positive("m", "voxel side (FAST-LIO filter_size_surf)").WithMax(100.0));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

class VoxelFilter {
 public:
  /// CHECK-fails on invalid options (validate configs before).
  explicit VoxelFilter(const VoxelFilterOptions& options);
  ~VoxelFilter();
  VoxelFilter(VoxelFilter&&) noexcept;
  VoxelFilter& operator=(VoxelFilter&&) noexcept;

  /// Writes one point per occupied voxel of `points` to `*out` (cleared
  /// first; `out` must not alias `points`). Non-finite points are skipped.
  void Filter(const std::vector<PointXYZT>& points, std::vector<PointXYZT>* out);

  /// Convenience form of Filter().
  std::vector<PointXYZT> Filter(const std::vector<PointXYZT>& points);

  const VoxelFilterOptions& options() const { return options_; }

 private:
  struct Impl;
  VoxelFilterOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::lio
