// Counters of what a BagReader delivered and what it skipped, and why.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace swarmlio::io {

/// Why a record (or a single point) was not delivered.
enum class SkipReason {
  kImuNonFinite = 0,  // IMU sample with a NaN/inf rate or acceleration
  kImuNonMonotonic,   // IMU stamp older than the previous IMU stamp
  kPointNonFinite,    // one LiDAR point with a NaN/inf coordinate or time (point dropped)
  kScanEmpty,         // scan with no points (or none left after dropping points)
  kScanNonMonotonic,  // scan stamp older than the previous scan stamp
  kPoseNonFinite,     // ground-truth pose with a NaN/inf value
  kPoseNonMonotonic,  // ground-truth stamp older than the previous one
  kMalformedMessage,  // undecodable message (only with skip_malformed_messages)
  kNumReasons
};

inline constexpr size_t kNumSkipReasons = static_cast<size_t>(SkipReason::kNumReasons);

/// Short snake_case name of a reason ("imu_non_finite", ...).
const char* SkipReasonName(SkipReason reason);

struct ReadStats {
  int64_t imu_samples = 0;                         // delivered IMU samples
  int64_t scans = 0;                               // delivered scans
  int64_t points = 0;                              // points in delivered scans
  int64_t ground_truth_poses = 0;                  // delivered poses
  int64_t scans_without_point_time = 0;            // delivered PointCloud2 scans with no time field
  std::array<int64_t, kNumSkipReasons> skipped{};  // indexed by SkipReason

  int64_t Skipped(SkipReason reason) const { return skipped[static_cast<size_t>(reason)]; }
  int64_t TotalSkipped() const;

  /// Multi-line human-readable summary (one "name: count" per line).
  std::string ToString() const;
};

}  // namespace swarmlio::io
