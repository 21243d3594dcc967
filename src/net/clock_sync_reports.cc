// Both ends of a pair: drone j reports its own estimate of teammate k's clock
// offset to k, and k fuses it with its own estimate of j's (docs/network.md
// "Both ends of a pair"). Each end's exchanges use the arrival times that end
// recorded, so the two estimates are only partly correlated (the same
// packets serve both, paired differently): fusing them is worth about 1.3 in
// rms under a symmetric jitter (measured in the simulation).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "swarmlio/net/clock_sync.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net {
namespace {

// Correlation assumed between the two ends' errors when fusing (the
// simulation of docs/network.md measures about 0.2 on a jittery link).
constexpr double kEndCorrelation = 0.2;
// A report is resolved against our estimate and used only when the two agree
// within this many sigmas (plus the quantization).
constexpr double kReportSigmas = 5.0;
// Reports older than this (our clock) are not used.
constexpr int64_t kReportMaxAgeNs = 10'000'000'000;
// Half the residue's range: our estimate and the report must agree within it.
constexpr int64_t kResidueHalfRangeNs = kOffsetReportStepNs * 32768;

int64_t RoundDiv(int64_t value, int64_t step) {
  const int64_t q = value / step, r = value % step;
  if (2 * r >= step) return q + 1;
  if (2 * r < -step) return q - 1;
  return q;
}

}  // namespace

bool ClockSync::ReportFor(int64_t now_ns, ClockOffsetReport* report) {
  if (!echo_mode() || options_.report_period_s <= 0.0) return false;
  const int64_t period_ns = std::llround(options_.report_period_s * 1e9);
  const double max_std_ns =
      static_cast<double>(ClockOffsetReport::kMaxStdCode * kOffsetReportStdStepNs);
  Teammate* chosen = nullptr;
  int chosen_id = -1;
  for (auto& [id, teammate] : teammates_) {
    if (teammate.last_report_ns != std::numeric_limits<int64_t>::min() &&
        now_ns - teammate.last_report_ns < period_ns) {
      continue;
    }
    const ClockOffsetEstimate e = teammate.estimator.Estimate(now_ns);
    if (e.num_samples < ClockOffsetEstimator::kRobustFitMinSamples ||
        !(e.std_ns <= max_std_ns)) {
      continue;
    }
    if (chosen == nullptr || teammate.report_order < chosen->report_order) {
      chosen = &teammate;
      chosen_id = id;
    }
  }
  if (chosen == nullptr) return false;
  const ClockOffsetEstimate e = chosen->estimator.Estimate(now_ns);
  report->teammate_id = chosen_id;
  report->offset_residue =
      static_cast<uint16_t>(static_cast<uint64_t>(RoundDiv(e.offset_ns, kOffsetReportStepNs)));
  report->std_code = static_cast<int>(std::clamp<double>(
      std::ceil(e.std_ns / static_cast<double>(kOffsetReportStdStepNs)), 1.0,
      ClockOffsetReport::kMaxStdCode));
  chosen->last_report_ns = now_ns;
  chosen->report_order = ++reports_made_;
  ++chosen->stats.reports_sent;
  return true;
}

void ClockSync::NoteReport(const ClockOffsetReport& report, int64_t stamp_ns, Teammate* teammate) {
  // The reporting state's stamp on our clock, and our own estimate there.
  int64_t local_ns = 0;
  if (!teammate->estimator.ToLocal(stamp_ns, &local_ns)) {
    ++teammate->stats.reports_rejected;
    return;
  }
  const ClockOffsetEstimate own = teammate->estimator.Estimate(local_ns);
  if (own.num_samples < ClockOffsetEstimator::kRobustFitMinSamples) {
    ++teammate->stats.reports_rejected;
    return;
  }
  // It reports its estimate of our offset, about -own.offset_ns: resolve the
  // residue around that.
  const int64_t expected = RoundDiv(-own.offset_ns, kOffsetReportStepNs);
  const int16_t wrap = static_cast<int16_t>(
      static_cast<uint16_t>(report.offset_residue - static_cast<uint16_t>(expected)));
  const int64_t reported_ns = -(expected + wrap) * kOffsetReportStepNs;  // its offset
  const double std_ns = static_cast<double>(report.std_code * kOffsetReportStdStepNs);
  const double var_ns2 = std_ns * std_ns;
  const double difference = static_cast<double>(reported_ns - own.offset_ns);
  if (std::abs(difference) >= static_cast<double>(kResidueHalfRangeNs) ||
      std::abs(difference) >
          kReportSigmas * std::sqrt(own.std_ns * own.std_ns + var_ns2) + kOffsetReportStepNs) {
    ++teammate->stats.reports_rejected;
    return;
  }
  teammate->have_report = true;
  teammate->report_local_ns = local_ns;
  teammate->report_offset_ns = reported_ns;
  teammate->report_var_ns2 = var_ns2;
  teammate->report_resets = teammate->estimator.resets();
  ++teammate->stats.reports_used;
}

ClockOffsetEstimate ClockSync::Fused(const Teammate& teammate, int64_t now_ns) const {
  ClockOffsetEstimate e = teammate.estimator.Estimate(now_ns);
  const int64_t age_ns = now_ns - teammate.report_local_ns;
  if (e.num_samples < ClockOffsetEstimator::kRobustFitMinSamples || !teammate.have_report || teammate.report_resets != teammate.estimator.resets() ||
      age_ns > kReportMaxAgeNs || age_ns < -kReportMaxAgeNs) {
    return e;
  }
  // The report carried to now with our drift estimate.
  const double dt_s = static_cast<double>(age_ns) * 1e-9;
  const double reported = static_cast<double>(teammate.report_offset_ns) + e.drift_ppm * 1e3 * dt_s;
  const double drift_std = e.drift_std_ppm * 1e3 * dt_s;  // [ns]
  const double vr = teammate.report_var_ns2 + drift_std * drift_std;
  const double vo = e.std_ns * e.std_ns;
  if (!(vr > 0.0) || !(vo > 0.0)) return e;
  const double w = vo / (vo + vr);  // the report's weight
  const double shift = w * (reported - static_cast<double>(e.offset_ns));
  e.offset_ns += std::llround(shift);
  e.std_ns = std::sqrt((1 - w) * (1 - w) * vo + w * w * vr +
                       2.0 * kEndCorrelation * w * (1 - w) * std::sqrt(vo * vr));
  e.report_weight = w;
  return e;
}

ClockOffsetEstimate ClockSync::Estimate(int teammate_id, int64_t now_ns) const {
  auto it = teammates_.find(teammate_id);
  if (it == teammates_.end()) return ClockOffsetEstimate();
  return Fused(it->second, now_ns);
}

bool ClockSync::ToLocal(int teammate_id, int64_t remote_ns, int64_t* local_ns) const {
  auto it = teammates_.find(teammate_id);
  if (it == teammates_.end()) return false;
  const Teammate& teammate = it->second;
  int64_t first = 0;
  if (!teammate.estimator.ToLocal(remote_ns, &first)) return false;
  // The fused offset differs from ours by a shift that changes slowly with
  // time: evaluated at our own mapping, then applied.
  const int64_t shift = Fused(teammate, first).offset_ns - teammate.estimator.Estimate(first).offset_ns;
  int64_t shifted = 0;
  if (shift == 0) {
    *local_ns = first;
    return true;
  }
  return !__builtin_sub_overflow(remote_ns, shift, &shifted) &&
         teammate.estimator.ToLocal(shifted, local_ns);
}

}  // namespace swarmlio::net
