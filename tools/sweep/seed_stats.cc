#include "seed_stats.h"

#include <algorithm>
#include <cmath>

namespace swarmlio::sweep {

double StudentT975(int dof) {
  static const double kTable[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                  2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                  2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                  2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return 0.0;
  if (dof <= 30) return kTable[dof - 1];
  // Between the table's end (30: 2.042) and the normal limit: linear in 1/dof
  // (40: 2.021, 60: 2.000, 120: 1.980 exact; this gives 2.021, 2.001, 1.980).
  return 1.95996 + (2.042 - 1.95996) * 30.0 / dof;
}

SeedStats ComputeSeedStats(const std::vector<double>& values) {
  SeedStats s;
  s.n = static_cast<int>(values.size());
  if (s.n == 0) return s;
  double sum = 0.0;
  for (double v : values) sum += v;
  s.mean = sum / s.n;
  double ss = 0.0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.std = s.n > 1 ? std::sqrt(ss / (s.n - 1)) : 0.0;
  s.min = *std::min_element(values.begin(), values.end());
  s.max = *std::max_element(values.begin(), values.end());
  const double half = s.n > 1 ? StudentT975(s.n - 1) * s.std / std::sqrt(s.n) : 0.0;
  s.ci95_lo = s.mean - half;
  s.ci95_hi = s.mean + half;
  return s;
}

}  // namespace swarmlio::sweep
