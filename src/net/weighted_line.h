// The weighted least-squares line of the clock-offset fits (internal):
// y = a + b x with a prior b ~ N(0, 1 / prior_info) on the slope, the weights
// divided by `scale` (a common variance scale). Used by ClockOffsetEstimator
// and the outlier model (offset_outliers.h).
#pragma once

#include <cstddef>
#include <vector>

namespace swarmlio::net::internal {

struct WeightedLine {
  double a = 0.0, b = 0.0;
  double caa = 0.0, cab = 0.0, cbb = 0.0;  // covariance of (a, b)
};

/// False, and *line untouched, when the normal matrix is singular.
inline bool FitWeightedLine(const std::vector<double>& x, const std::vector<double>& y,
                            const std::vector<double>& w, double scale, double prior_info,
                            WeightedLine* line) {
  double sw = 0, swx = 0, swxx = 0, swy = 0, swxy = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    sw += w[i];
    swx += w[i] * x[i];
    swxx += w[i] * x[i] * x[i];
    swy += w[i] * y[i];
    swxy += w[i] * x[i] * y[i];
  }
  const double n00 = sw / scale, n01 = swx / scale, n11 = swxx / scale + prior_info;
  const double det = n00 * n11 - n01 * n01;
  if (!(det > 0)) return false;
  line->caa = n11 / det;
  line->cab = -n01 / det;
  line->cbb = n00 / det;
  line->a = line->caa * (swy / scale) + line->cab * (swxy / scale);
  line->b = line->cab * (swy / scale) + line->cbb * (swxy / scale);
  return true;
}

}  // namespace swarmlio::net::internal
