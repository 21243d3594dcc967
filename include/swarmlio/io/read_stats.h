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
  kDamagedRecord,     // record of a truncated/corrupt bag that could not be read (see recovery)
  kNumReasons
};

inline constexpr size_t kNumSkipReasons = static_cast<size_t>(SkipReason::kNumReasons);

/// Short snake_case name of a reason ("imu_non_finite", ...).
const char* SkipReasonName(SkipReason reason);

/// What was recovered from a damaged bag: one that is not indexed (the
/// recorder died before closing it) or whose index is cut off or unreadable
/// (the file was truncated). Such a bag is read by scanning its chunk and
/// message records in file order, as `rosbag reindex` does; every complete
/// message before the damage is read, the rest is counted here.
struct BagRecoveryStats {
  bool recovered = false;       // true: the bag was read by a record scan, not its index
  std::string reason;           // why the index could not be used
  int64_t messages = 0;         // complete message records found
  int64_t damaged_records = 0;  // records cut off or unreadable (partial message, chunk, ...)
  uint64_t damage_offset = 0;   // file offset of the first damaged record (0: none)
  uint64_t damaged_bytes = 0;   // bytes that could not be read (from the damage on)

  /// One line: "recovered N messages from an unindexed bag (...); M damaged records, B bytes
  /// unreadable from offset O", or "" when not recovered.
  std::string Summary() const;
};

struct ReadStats {
  int64_t imu_samples = 0;                         // delivered IMU samples
  int64_t scans = 0;                               // delivered scans
  int64_t points = 0;                              // points in delivered scans
  int64_t ground_truth_poses = 0;                  // delivered poses
  int64_t scans_without_point_time = 0;            // delivered PointCloud2 scans with no time field
  int64_t scans_point_time_from_azimuth = 0;       // of those, per-point time from azimuth
  std::array<int64_t, kNumSkipReasons> skipped{};  // indexed by SkipReason
  BagRecoveryStats recovery;  // set when the bag was damaged; skipped[kDamagedRecord] mirrors
                              // recovery.damaged_records

  int64_t Skipped(SkipReason reason) const { return skipped[static_cast<size_t>(reason)]; }
  int64_t TotalSkipped() const;

  /// Multi-line human-readable summary (one "name: count" per line, then a
  /// "recovery: ..." line for a damaged bag).
  std::string ToString() const;

  /// How per-point time was obtained, one line: "per-point time field",
  /// "reconstructed from azimuth (N scans without a time field)" or "none: N
  /// scans without a time field read as one instant" (Livox CustomMsg and
  /// clouds with a time field: "per-point time field").
  std::string PointTimeSummary() const;
};

}  // namespace swarmlio::io
