#include "swarmlio/io/read_stats.h"

#include <sstream>

namespace swarmlio::io {

const char* SkipReasonName(SkipReason reason) {
  switch (reason) {
    case SkipReason::kImuNonFinite:
      return "imu_non_finite";
    case SkipReason::kImuNonMonotonic:
      return "imu_non_monotonic";
    case SkipReason::kPointNonFinite:
      return "point_non_finite";
    case SkipReason::kScanEmpty:
      return "scan_empty";
    case SkipReason::kScanNonMonotonic:
      return "scan_non_monotonic";
    case SkipReason::kPoseNonFinite:
      return "pose_non_finite";
    case SkipReason::kPoseNonMonotonic:
      return "pose_non_monotonic";
    case SkipReason::kMalformedMessage:
      return "malformed_message";
    case SkipReason::kDamagedRecord:
      return "damaged_record";
    case SkipReason::kNumReasons:
      break;
  }
  return "?";
}

std::string BagRecoveryStats::Summary() const {
  if (!recovered) return "";
  std::ostringstream os;
  os << "recovered " << messages << " messages by scanning the records (" << reason << ")";
  if (damaged_records > 0 || damaged_bytes > 0) {
    os << "; " << damaged_records << " damaged records, " << damaged_bytes
       << " bytes unreadable from offset " << damage_offset;
  } else {
    os << "; no message lost";
  }
  return os.str();
}

int64_t ReadStats::TotalSkipped() const {
  int64_t total = 0;
  for (int64_t count : skipped) total += count;
  return total;
}

std::string ReadStats::ToString() const {
  std::ostringstream os;
  os << "imu_samples: " << imu_samples << "\n"
     << "scans: " << scans << "\n"
     << "points: " << points << "\n"
     << "ground_truth_poses: " << ground_truth_poses << "\n"
     << "scans_without_point_time: " << scans_without_point_time << "\n"
     << "scans_point_time_from_azimuth: " << scans_point_time_from_azimuth << "\n";
  for (size_t i = 0; i < kNumSkipReasons; ++i) {
    os << "skipped." << SkipReasonName(static_cast<SkipReason>(i)) << ": " << skipped[i] << "\n";
  }
  if (recovery.recovered) os << "recovery: " << recovery.Summary() << "\n";
  return os.str();
}

std::string ReadStats::PointTimeSummary() const {
  if (scans_without_point_time == 0) return "per-point time field";
  const int64_t instant = scans_without_point_time - scans_point_time_from_azimuth;
  std::ostringstream os;
  if (scans_point_time_from_azimuth > 0) {
    os << "reconstructed from azimuth (" << scans_point_time_from_azimuth
       << " scans without a time field)";
    if (instant > 0) os << "; ";
  }
  if (instant > 0) {
    os << "none: " << instant << " scans without a time field read as one instant";
  }
  return os.str();
}

}  // namespace swarmlio::io
