// Summary statistics of a list of errors, as evo reports them.
#pragma once

#include <cstddef>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::eval {

struct ErrorStatistics {
  size_t count = 0;   // number of errors (pairs)
  double rmse = 0.0;  // sqrt(mean(e^2))
  double mean = 0.0;
  double median = 0.0;  // mean of the two middle values for an even count
  double std = 0.0;     // population standard deviation (numpy's default)
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum(e^2)
};

/// Errors: an empty list, a non-finite value.
Status ComputeErrorStatistics(const std::vector<double>& errors, ErrorStatistics* statistics);

/// The `fraction` quantile (0 = min, 0.5 = median, 1 = max) with linear
/// interpolation between order statistics (numpy's default); 0 for an empty list.
double Percentile(std::vector<double> values, double fraction);

}  // namespace swarmlio::eval
