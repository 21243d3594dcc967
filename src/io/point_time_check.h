// Sanity check of PointCloud2 per-point times against the scan period: a
// wrong point_time_unit scales every offset by a power of 1000, so a scan
// that spans 0.1 s reads as 100 s (unit too fine) or 0.1 ms (too coarse).
//
// With P the scan period (EstimateScanPeriodS) and U = max(2 P, 0.5 s):
//   - a span above U is an error;
//   - a span below P / 200 is an error when the scan has at least
//     kMinPointsForShortSpan points and another unit makes it fit
//     [P / 4, U] (a real scan covers most of its period);
//   - offsets further than max(10 P, 2 s) from the header stamp are an
//     error (per-point times that are absolute, not relative).
// Errors name the option (point_time_unit, i.e. a preset's
// lidar.timestamp_unit) and the unit that makes the span fit.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/sensors/lidar_formats.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

inline constexpr double kDefaultScanPeriodS = 0.1;
inline constexpr double kMinScanPeriodS = 1e-3;
inline constexpr double kMaxScanPeriodS = 1.0;
inline constexpr size_t kMinPointsForShortSpan = 100;

/// Median of the positive differences of consecutive bag times [s], clamped
/// to [kMinScanPeriodS, kMaxScanPeriodS]; kDefaultScanPeriodS without any.
double EstimateScanPeriodS(const std::vector<int64_t>& bag_times_ns);

/// "" if the per-point times of `scan` (offset_time_s, read in `unit` from
/// the field `time_field`) fit `scan_period_s`, else the problem.
/// `period_measured`: P came from the bag (else it is the default).
std::string CheckPointTimeSpan(const LidarScan& scan,
                               TimestampUnit unit,
                               const std::string& time_field,
                               double scan_period_s,
                               bool period_measured);

/// A duration for messages: "27.8 h", "15 min", "99.9 s", "2 ms", "0.1 us".
std::string FormatDuration(double seconds);

}  // namespace swarmlio::io::internal
