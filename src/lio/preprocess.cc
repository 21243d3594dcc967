#include "swarmlio/lio/preprocess.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "swarmlio/common/check.h"

namespace swarmlio::lio {
namespace {

constexpr uint8_t kLivoxReturnMask = 0x30;   // tag bits 5:4: return number
constexpr uint8_t kLivoxFirstReturn = 0x10;  // return 1 (0x00: return 0 / single)
constexpr uint8_t kLivoxSpatialNoiseMask = 0x03;  // tag bits 1:0: spatial confidence

VoxelFilterOptions FilterOptions(const PreprocessOptions& options) {
  VoxelFilterOptions filter;
  // A disabled filter still needs a valid leaf; Run() bypasses it.
  if (options.voxel_leaf_size_m > 0.0) filter.leaf_size_m = options.voxel_leaf_size_m;
  return filter;
}

}  // namespace

std::string PreprocessOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  if (!(blind_range_m < max_range_m)) {
    std::ostringstream os;
    os << "blind_range_m: must be below max_range_m (" << blind_range_m << " >= " << max_range_m
       << ")";
    return os.str();
  }
  return {};
}

PreprocessOptions PreprocessOptionsFor(const LidarOptions& lidar) {
  PreprocessOptions options;
  options.blind_range_m = lidar.blind_range_m;
  options.max_range_m = lidar.max_range_m;
  options.num_lines = lidar.num_lines;
  switch (lidar.type) {
    case LidarType::kLivoxAvia:  // Swarm-LIO2 avia.yaml
      options.point_stride = 4;
      options.voxel_leaf_size_m = 0.2;
      options.livox_tag_filter = true;
      break;
    case LidarType::kLivoxMid360:  // Swarm-LIO2 mid360.yaml
      options.point_stride = 2;
      options.voxel_leaf_size_m = 0.2;
      options.livox_tag_filter = true;
      break;
    case LidarType::kSpinning:  // Swarm-LIO2 code defaults (FAST-LIO filter_size_surf 0.5)
      options.point_stride = 2;
      options.voxel_leaf_size_m = 0.5;
      options.livox_tag_filter = false;
      break;
  }
  return options;
}

Preprocess::Preprocess(const PreprocessOptions& options, const Eigen::Matrix3d& R_imu_lidar,
                       const Eigen::Vector3d& p_lidar_in_imu_m)
    : options_(options),
      R_imu_lidar_(R_imu_lidar),
      p_lidar_in_imu_m_(p_lidar_in_imu_m),
      voxel_filter_(FilterOptions(options)) {
  const std::string error = options_.Validate();
  CHECK(error.empty()) << "PreprocessOptions: " << error;
}

void Preprocess::Run(const LidarScan& scan, std::vector<PointXYZT>* out, PreprocessStats* stats) {
  CHECK(out != nullptr);
  PreprocessStats s;
  s.input = static_cast<int64_t>(scan.points.size());
  const bool downsample = options_.voxel_leaf_size_m > 0.0;
  std::vector<PointXYZT>& kept = downsample ? kept_ : *out;
  kept.clear();
  kept.reserve(scan.points.size() / static_cast<size_t>(options_.point_stride) + 1);
  const double blind2 = options_.blind_range_m * options_.blind_range_m;
  const double max2 = options_.max_range_m * options_.max_range_m;
  int64_t valid = 0;
  for (const LidarPoint& lp : scan.points) {
    const Eigen::Vector3d p_L(lp.x, lp.y, lp.z);
    if (!p_L.allFinite() || !std::isfinite(lp.offset_time_s)) {
      ++s.non_finite;
      continue;
    }
    if (options_.num_lines > 0 && lp.line >= options_.num_lines) {
      ++s.line_rejected;
      continue;
    }
    if (options_.livox_tag_filter) {
      const uint8_t ret = lp.tag & kLivoxReturnMask;
      if (ret != 0x00 && ret != kLivoxFirstReturn) {
        ++s.tag_rejected;
        continue;
      }
    }
    if (options_.livox_reject_noise && (lp.tag & kLivoxSpatialNoiseMask) != 0) {
      ++s.tag_rejected;
      continue;
    }
    if (valid++ % options_.point_stride != 0) {
      ++s.stride_skipped;
      continue;
    }
    const double r2 = p_L.squaredNorm();
    if (r2 < blind2) {
      ++s.blind;
      continue;
    }
    if (r2 > max2) {
      ++s.too_far;
      continue;
    }
    PointXYZT point;
    point.p_in_b = R_imu_lidar_ * p_L + p_lidar_in_imu_m_;
    point.time_s = lp.offset_time_s;
    point.reflectivity = lp.reflectivity;
    kept.push_back(point);
  }
  if (downsample) {
    voxel_filter_.Filter(kept_, out);
    s.voxel_merged = static_cast<int64_t>(kept_.size() - out->size());
  }
  std::stable_sort(out->begin(), out->end(),
                   [](const PointXYZT& a, const PointXYZT& b) { return a.time_s < b.time_s; });
  s.output = static_cast<int64_t>(out->size());
  if (stats != nullptr) *stats = s;
}

}  // namespace swarmlio::lio
