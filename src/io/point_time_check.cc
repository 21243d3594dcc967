#include "src/io/point_time_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::io::internal {
namespace {

constexpr std::array<TimestampUnit, 4> kUnits = {
    TimestampUnit::kSecond, TimestampUnit::kMillisecond, TimestampUnit::kMicrosecond,
    TimestampUnit::kNanosecond};

std::string Number(double value, int digits = 6) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.*g", digits, value);
  return text;
}

const char* UnitName(TimestampUnit unit) { return config::EnumToString(unit); }

// The unit other than `configured` whose reading of `raw_span` fits
// [low, high] best (closest to `period` in ratio); false if none fits.
bool BestUnit(double raw_span,
              TimestampUnit configured,
              double period,
              double low,
              double high,
              TimestampUnit* best) {
  bool found = false;
  double best_distance = 0.0;
  for (TimestampUnit unit : kUnits) {
    if (unit == configured) continue;
    const double span_s = raw_span / TimestampUnitTicksPerSecond(unit);
    if (span_s < low || span_s > high) continue;
    const double distance = std::abs(std::log(span_s / period));
    if (!found || distance < best_distance) {
      found = true;
      best_distance = distance;
      *best = unit;
    }
  }
  return found;
}

std::string SetUnitHint(TimestampUnit unit) {
  return std::string("set point_time_unit: ") + UnitName(unit) +
         " (in a sensor preset or manifest: lidar.timestamp_unit: " + UnitName(unit) + ")";
}

}  // namespace

double EstimateScanPeriodS(const std::vector<int64_t>& bag_times_ns) {
  std::vector<int64_t> steps;
  for (size_t i = 1; i < bag_times_ns.size(); ++i) {
    const int64_t step = bag_times_ns[i] - bag_times_ns[i - 1];
    if (step > 0) steps.push_back(step);
  }
  if (steps.empty()) return kDefaultScanPeriodS;
  const size_t middle = steps.size() / 2;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(middle), steps.end());
  const double period_s = static_cast<double>(steps[middle]) * 1e-9;
  return std::clamp(period_s, kMinScanPeriodS, kMaxScanPeriodS);
}

std::string FormatDuration(double seconds) {
  const double magnitude = std::abs(seconds);
  if (magnitude >= 3600.0) return Number(seconds / 3600.0) + " h";
  if (magnitude >= 600.0) return Number(seconds / 60.0) + " min";
  if (magnitude >= 1.0 || magnitude == 0.0) return Number(seconds) + " s";
  if (magnitude >= 1e-3) return Number(seconds * 1e3) + " ms";
  if (magnitude >= 1e-6) return Number(seconds * 1e6) + " us";
  return Number(seconds * 1e9) + " ns";
}

std::string CheckPointTimeSpan(const LidarScan& scan,
                               TimestampUnit unit,
                               const std::string& time_field,
                               double scan_period_s,
                               bool period_measured) {
  if (scan.points.size() < 2) return "";
  double min_s = scan.points.front().offset_time_s;
  double max_s = min_s;
  for (const LidarPoint& p : scan.points) {
    min_s = std::min(min_s, p.offset_time_s);
    max_s = std::max(max_s, p.offset_time_s);
  }
  const double period = scan_period_s;
  const double high = std::max(2.0 * period, 0.5);
  const double low = period / 200.0;
  const double span_s = max_s - min_s;
  const double raw_span = span_s * TimestampUnitTicksPerSecond(unit);
  const std::string period_text =
      "scan period " + FormatDuration(period) +
      (period_measured ? " (median spacing of the LiDAR messages)" : " (assumed)");
  const std::string head = "per-point time field '" + time_field + "' spans " +
                           Number(raw_span, 10) + " (in point_time_unit '" + UnitName(unit) +
                           "' that is " + FormatDuration(span_s) + ")";
  TimestampUnit best = unit;
  if (span_s > high) {
    std::string message = head + ", longer than a scan can be (" + period_text + "); ";
    if (BestUnit(raw_span, unit, period, period / 4.0, high, &best)) {
      message += std::string("with '") + UnitName(best) + "' it is " +
                 FormatDuration(raw_span / TimestampUnitTicksPerSecond(best)) + ": " +
                 SetUnitHint(best);
    } else {
      message +=
          "no unit gives a plausible span: check point_time_field, or set "
          "check_point_time_span: false";
    }
    return message;
  }
  if (scan.points.size() >= kMinPointsForShortSpan && span_s > 0.0 && span_s < low &&
      BestUnit(raw_span, unit, period, period / 4.0, high, &best)) {
    return head + ", far shorter than a scan (" + period_text + "); with '" + UnitName(best) +
           "' it is " + FormatDuration(raw_span / TimestampUnitTicksPerSecond(best)) + ": " +
           SetUnitHint(best);
  }
  const double far = std::max(10.0 * period, 2.0);
  const double farthest = std::max(std::abs(min_s), std::abs(max_s));
  if (farthest > far) {
    return "per-point time field '" + time_field + "' puts points " + FormatDuration(farthest) +
           " from the header stamp (in point_time_unit '" + UnitName(unit) +
           "'); per-point times must be relative to the header stamp, these look absolute "
           "(or the unit is wrong); set check_point_time_span: false to read them anyway";
  }
  return "";
}

}  // namespace swarmlio::io::internal
