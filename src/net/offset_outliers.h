// Exchanges that no clock offset explains (internal to ClockOffsetEstimator).
//
// Each exchange i gives an offset sample y_i at local time x_i, with round
// trip d_i; its error is at most d_i / 2, since both one-way delays are >= 0.
// The samples are modelled as a mixture around the line a + b x:
//   inlier  (1 - eps):  y_i ~ N(a + b x_i, s2)
//   outlier eps:        y_i uniform within +-d_i / 2 of the line
// fitted by EM (responsibilities; weighted least squares of a, b with the
// drift prior; the inliers' variance; eps the mean outlier responsibility)
// from a start the outliers cannot move (medians of the window's halves).
//
// What it is for: netem's "reorder" (and any path with a fast lane) lets some
// packets skip the path delay. An exchange with one fast leg is then off by
// half the path delay, and its round trip is the *shortest* in the window,
// so a least-delay filter trusts exactly these. The inliers' N(0, s2) does
// not depend on the round trip, so such an exchange is as far out as it is
// wrong, and the uniform component takes it. Packets held back on one leg
// (queueing) are off by their excess delay; when that is many s2 they are
// flagged too, and the estimator's delay weighting handles the rest.
#pragma once

#include <vector>

namespace swarmlio::net::internal {

struct OffsetSamples {
  std::vector<double> x;           // local time relative to a reference [s]
  std::vector<double> y;           // offset sample relative to a reference offset [ns]
  std::vector<double> round_trip;  // d_i [ns]
  double floor_ns = 0;             // lower bound of sqrt(s2) (stamping noise) [ns]
  double prior_info = 0;           // 1 / prior variance of the drift b [s^2 / ns^2]
};

/// Per exchange, the posterior probability that it is an outlier (same
/// order as the input; all zero for fewer than 3 samples). Deterministic.
std::vector<double> OffsetOutlierProbabilities(const OffsetSamples& samples);

}  // namespace swarmlio::net::internal
