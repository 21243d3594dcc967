// Exchanges that no clock offset explains: model and reasons in the header.
#include "src/net/offset_outliers.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "src/net/weighted_line.h"

namespace swarmlio::net::internal {
namespace {

constexpr int kEmIterations = 15;
constexpr double kConvergedResponsibility = 1e-3;
constexpr double kStartOutlierFraction = 0.1;
constexpr double kMinOutlierFraction = 1e-3;
constexpr double kMaxOutlierFraction = 0.5;
constexpr size_t kLeastDelayStarts = 2;
// The lower quartile of |N(0, 1)|.
constexpr double kLowerQuartileOfAbsNormal = 0.3186;
constexpr double kPi = 3.14159265358979323846;

double Median(std::vector<double> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

/// The inliers' line (weights: responsibilities), from and into (a, b).
void SolveLine(const OffsetSamples& in, const std::vector<double>& w, double* a, double* b) {
  WeightedLine line;
  if (!FitWeightedLine(in.x, in.y, w, 1.0, in.prior_info, &line)) return;
  *a = line.a;
  *b = line.b;
}

/// EM from (a, b, s2); returns the log-likelihood and the outlier probabilities.
double RunEm(const OffsetSamples& in, double a, double b, double s2, std::vector<double>* outlier) {
  const size_t n = in.x.size();
  const double floor2 = in.floor_ns * in.floor_ns;
  double eps = kStartOutlierFraction;
  std::vector<double> density(n), inlier(n), r2(n);
  for (size_t i = 0; i < n; ++i) {
    density[i] = 1.0 / std::max(in.round_trip[i], 10.0 * in.floor_ns);
  }
  double log_likelihood = 0;
  for (int iteration = 0; iteration <= kEmIterations; ++iteration) {
    // E step (the last pass only scores; so does one that changed no
    // responsibility by kConvergedResponsibility).
    double inliers = 0, change = 0;
    log_likelihood = 0;
    const double norm = 1.0 / std::sqrt(2.0 * kPi * s2);
    for (size_t i = 0; i < n; ++i) {
      const double ri = in.y[i] - a - b * in.x[i];
      r2[i] = ri * ri;
      const double g = (1.0 - eps) * norm * std::exp(-0.5 * r2[i] / s2);
      const double o = eps * density[i];
      const double p = g + o > 0 ? g / (g + o) : 0.0;
      change = std::max(change, std::abs(p - inlier[i]));
      inlier[i] = p;
      inliers += p;
      log_likelihood += std::log(std::max(g + o, std::numeric_limits<double>::min()));
    }
    if (iteration == kEmIterations || (iteration > 0 && change < kConvergedResponsibility)) break;
    // M step.
    eps = std::clamp(1.0 - inliers / static_cast<double>(n), kMinOutlierFraction,
                     kMaxOutlierFraction);
    double weighted = 0;
    for (size_t i = 0; i < n; ++i) weighted += inlier[i] * r2[i];
    if (inliers > 2.0) s2 = std::max(floor2, weighted / (inliers - 2.0));
    SolveLine(in, inlier, &a, &b);
  }
  outlier->resize(n);
  for (size_t i = 0; i < n; ++i) (*outlier)[i] = 1.0 - inlier[i];
  return log_likelihood;
}

}  // namespace

std::vector<double> OffsetOutlierProbabilities(const OffsetSamples& in) {
  const size_t n = in.x.size();
  std::vector<double> outlier(n, 0.0);
  if (n < 3) return outlier;
  // Several starts, the likeliest result wins (from one start, EM can settle
  // on a cluster of fast-lane exchanges when a short window holds nearly as
  // many of them as of the others):
  //  - the median offset, no drift;
  //  - the drift from the medians of the window's two halves (in time);
  //  - the offsets of the kLeastDelayStarts exchanges with the shortest round
  //    trips, no drift: when both legs were fast, the exchange is pinned to
  //    within d / 2 of the true offset.
  // The scale from the lower quartile of the absolute residuals (a cluster
  // of a quarter of the window is enough).
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t l, size_t r) { return in.x[l] < in.x[r]; });
  std::vector<double> x1, y1, x2, y2;
  for (size_t j = 0; j < n; ++j) {
    (j < n / 2 ? x1 : x2).push_back(in.x[order[j]]);
    (j < n / 2 ? y1 : y2).push_back(in.y[order[j]]);
  }
  double halves_b = 0;
  const double dx = Median(x2) - Median(x1);
  if (dx > 0) {
    const double limit = in.prior_info > 0 ? 3.0 / std::sqrt(in.prior_info) : 1e300;
    halves_b = std::clamp((Median(y2) - Median(y1)) / dx, -limit, limit);
  }
  struct StartLine {
    double a, b;
  };
  std::vector<StartLine> starts;
  std::vector<double> r(n), candidate;
  for (double b : {0.0, halves_b}) {
    for (size_t i = 0; i < n; ++i) r[i] = in.y[i] - b * in.x[i];
    starts.push_back({Median(r), b});
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t l, size_t m) { return in.round_trip[l] < in.round_trip[m]; });
  for (size_t j = 0; j < std::min(n, kLeastDelayStarts); ++j) {
    starts.push_back({in.y[order[j]], 0.0});
  }
  double best = -std::numeric_limits<double>::infinity();
  for (const StartLine& start : starts) {
    for (size_t i = 0; i < n; ++i) r[i] = std::abs(in.y[i] - start.a - start.b * in.x[i]);
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(n / 4), r.end());
    const double sigma = r[n / 4] / kLowerQuartileOfAbsNormal;
    const double s2 = std::max(in.floor_ns * in.floor_ns, sigma * sigma);
    const double log_likelihood = RunEm(in, start.a, start.b, s2, &candidate);
    if (log_likelihood > best) {
      best = log_likelihood;
      outlier = candidate;
    }
  }
  return outlier;
}

}  // namespace swarmlio::net::internal
