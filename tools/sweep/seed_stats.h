// Statistics of one figure over the seeds of a sweep: mean, sample standard
// deviation, min-max and the 95 % confidence interval of the mean from
// Student's t distribution (n - 1 degrees of freedom).
#pragma once

#include <vector>

namespace swarmlio::sweep {

struct SeedStats {
  int n = 0;
  double mean = 0.0;
  double std = 0.0;  // sample (n - 1); 0 for n = 1
  double min = 0.0;
  double max = 0.0;
  double ci95_lo = 0.0;  // mean -+ t * std / sqrt(n); the mean itself for n = 1
  double ci95_hi = 0.0;
};

/// Two-sided 95 % quantile t(0.975, dof) for dof >= 1 (a table up to 30, then
/// interpolated in 1/dof towards 1.96).
double StudentT975(int dof);

/// n = 0 for no values.
SeedStats ComputeSeedStats(const std::vector<double>& values);

}  // namespace swarmlio::sweep
