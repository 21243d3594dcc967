#include "swarmlio/eval/error_statistics.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace swarmlio::eval {

Status ComputeErrorStatistics(const std::vector<double>& errors, ErrorStatistics* statistics) {
  if (errors.empty()) return Status::InvalidArgument("statistics: no errors");
  for (size_t i = 0; i < errors.size(); ++i) {
    if (!std::isfinite(errors[i])) {
      return Status::InvalidArgument("statistics: error " + std::to_string(i) + " is not finite");
    }
  }
  const double n = static_cast<double>(errors.size());
  ErrorStatistics out;
  out.count = errors.size();
  double sum = 0.0;
  out.min = errors.front();
  out.max = errors.front();
  for (const double e : errors) {
    sum += e;
    out.sse += e * e;
    out.min = std::min(out.min, e);
    out.max = std::max(out.max, e);
  }
  out.mean = sum / n;
  out.rmse = std::sqrt(out.sse / n);
  double squared_deviation = 0.0;
  for (const double e : errors) squared_deviation += (e - out.mean) * (e - out.mean);
  out.std = std::sqrt(squared_deviation / n);
  std::vector<double> sorted = errors;
  const size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid), sorted.end());
  out.median = sorted[mid];
  if (sorted.size() % 2 == 0) {
    const double lower =
        *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid));
    out.median = 0.5 * (lower + out.median);
  }
  *statistics = out;
  return Status::Ok();
}

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double pos = std::clamp(fraction, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

}  // namespace swarmlio::eval
