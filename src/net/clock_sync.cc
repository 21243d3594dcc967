// Clock offset estimation from four-timestamp exchanges (math in the header
// and in docs/network.md, "Clock synchronisation").
#include "swarmlio/net/clock_sync.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

#include "src/net/offset_outliers.h"
#include "src/net/weighted_line.h"
#include "swarmlio/net/swarm_limits.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net {
namespace {

constexpr double kNsPerS = 1e9;
// A sample contradicts the fit when it is further from it than its own delay
// bound (d / 2), the fit's asymmetry bound (d_min / 2) and this many sigmas.
constexpr double kOutlierSigmas = 6.0;
// Variance scale: chi^2 / dof shrunk with this many pseudo degrees of freedom
// towards what the per-sample model and the round-trip spread say, so that a
// handful of exchanges does not claim more precision than they have.
constexpr double kScalePseudoDof = 2.0;
// Reweighting passes of the robust fit, and its Huber threshold [sigmas].
constexpr int kReweightIterations = 4;
constexpr double kHuberK = 2.0;
// Median absolute deviation to standard deviation (normal distribution).
constexpr double kMadToSigma = 1.4826;
// State echo: own state stamps remembered for the echoes (10 s at 10 Hz).
constexpr size_t kOwnStates = 100;

int64_t SecondsToNs(double s) { return std::llround(s * kNsPerS); }

bool Sub(int64_t a, int64_t b, int64_t* out) { return !__builtin_sub_overflow(a, b, out); }
bool Add(int64_t a, int64_t b, int64_t* out) { return !__builtin_add_overflow(a, b, out); }

// Round-trip statistics of the exchanges a fit uses.
struct DelayStatistics {
  int64_t min_delay_ns = 0;    // their minimum round trip
  double s0 = 0.0;             // the noise of an undelayed exchange [ns]
  double delay_noise = 0.0;    // half the round trips' robust std [ns]
  double median_excess = 0.0;  // half the median round trip's excess over the minimum [ns]
};

// Delay statistics. s0, the noise of an undelayed exchange, is the gap
// between the minimum and the lower quartile of the round trips: a
// symmetric jitter gives a wide gap, so the weights stay nearly uniform; a
// tight core with a queueing tail gives a small gap, so the tail is
// down-weighted by its excess delay. (A quartile rather than the median, so
// that the core wins while up to 3/4 of the exchanges are delayed.) Never
// below floor_ns, the timestamp noise.
DelayStatistics ComputeDelayStatistics(const std::vector<TimeSyncSample>& used, double floor_ns) {
  const size_t n = used.size();
  std::vector<int64_t> delays;
  delays.reserve(n);
  for (const TimeSyncSample& s : used) delays.push_back(s.delay_ns);
  std::sort(delays.begin(), delays.end());
  DelayStatistics stats;
  const int64_t min_delay_ns = delays.front();  // of the exchanges used
  stats.min_delay_ns = min_delay_ns;
  stats.s0 = std::max(floor_ns, static_cast<double>(delays[n / 4] - min_delay_ns));
  // For a symmetric jitter an exchange's error has half the round trip's
  // std: a second, independent guess of the noise (robust: MAD).
  std::vector<double> deviations(n);
  for (size_t i = 0; i < n; ++i) {
    deviations[i] = std::abs(static_cast<double>(delays[i] - delays[n / 2]));
  }
  std::nth_element(deviations.begin(), deviations.begin() + static_cast<std::ptrdiff_t>(n / 2),
                   deviations.end());
  stats.delay_noise = 0.5 * kMadToSigma * deviations[n / 2];
  stats.median_excess = 0.5 * static_cast<double>(delays[n / 2] - min_delay_ns);
  return stats;
}

// The samples of the line fit: x [s] and y [ns] relative to the base time
// and offset, the excess delay [ns] and the weights.
struct FitSamples {
  std::vector<double> xs, ys, excess, ws;
};

// Weighted least squares of y = a + b x with the drift prior; `scale`
// multiplies every sample's variance.
// (The prior keeps the normal matrix regular: the fit always succeeds.)
// Reweights samples->ws.
internal::WeightedLine FitRobustLine(FitSamples* samples,
                                     const DelayStatistics& delays,
                                     double prior_info) {
  const std::vector<double>& xs = samples->xs;
  const std::vector<double>& ys = samples->ys;
  const std::vector<double>& excess = samples->excess;
  std::vector<double>& ws = samples->ws;
  const size_t n = xs.size();
  const double s0 = delays.s0;
  std::vector<double> abs_residuals(n);
  internal::WeightedLine line;
  double &a = line.a, &b = line.b;
  auto solve = [&](double scale) {
    internal::FitWeightedLine(xs, ys, ws, scale, prior_info, &line);
  };
  solve(1.0);
  // Iteratively reweighted: a sample's noise is the residual scale sr plus
  // its excess delay, and a Huber weight tempers samples beyond kHuberK of
  // that. sr is measured on the core (the half of the exchanges with the
  // least excess delay), never below s0: with a symmetric jitter the
  // minimum-delay exchange is no better than the others, and this keeps it
  // from dominating; with a queueing tail the core is the undelayed part.
  const double median_excess = delays.median_excess;
  double sr = s0;
  for (int iteration = 0; n >= 3 && iteration < kReweightIterations; ++iteration) {
    abs_residuals.clear();
    for (size_t i = 0; i < n; ++i) {
      if (excess[i] <= median_excess) abs_residuals.push_back(std::abs(ys[i] - a - b * xs[i]));
    }
    const size_t core = abs_residuals.size();  // >= n / 2 + 1
    std::nth_element(abs_residuals.begin(),
                     abs_residuals.begin() + static_cast<std::ptrdiff_t>(core / 2),
                     abs_residuals.end());
    // Residuals of a 2-parameter fit are smaller than the noise by about sqrt((n-2)/n).
    const double correction = std::sqrt(static_cast<double>(n) / static_cast<double>(n - 2));
    sr = std::max(s0, kMadToSigma * correction * abs_residuals[core / 2]);
    for (size_t i = 0; i < n; ++i) {
      const double variance = sr * sr + excess[i] * excess[i];
      const double u = std::abs(ys[i] - a - b * xs[i]) / std::sqrt(variance);
      ws[i] = (u > kHuberK ? kHuberK / u : 1.0) / variance;
    }
    solve(1.0);
  }
  double chi2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double r = ys[i] - a - b * xs[i];
    chi2 += ws[i] * r * r;
  }
  // The variance scale: chi^2 / dof, shrunk towards what the delay spread
  // suggests (never below the model), so that a few exchanges that happen to
  // line up do not claim a precision (and a drift) they cannot have.
  const double dof = static_cast<double>(n) - 1.0;  // 2 parameters, the prior counts as one datum
  const double prior_ratio = std::max(1.0, (delays.delay_noise * delays.delay_noise) / (sr * sr));
  solve((chi2 + kScalePseudoDof * prior_ratio) / (dof + kScalePseudoDof));
  return line;
}

}  // namespace

std::string ClockSyncOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (error.empty() && min_samples > window_samples) {
    error = "min_samples: " + std::to_string(min_samples) + " exceeds window_samples (" +
            std::to_string(window_samples) + ")";
  }
  return error;
}

Status ReduceTimeSyncExchange(int64_t t1_ns, int64_t t2_ns, int64_t t3_ns, int64_t t4_ns,
                              TimeSyncSample* sample, int64_t stamp_step_ns) {
  int64_t round_trip = 0, turnaround = 0, forward = 0, backward = 0, sum = 0, delay = 0;
  if (!Sub(t4_ns, t1_ns, &round_trip) || !Sub(t3_ns, t2_ns, &turnaround) ||
      !Sub(t2_ns, t1_ns, &forward) || !Sub(t3_ns, t4_ns, &backward) ||
      !Add(forward, backward, &sum) || !Sub(round_trip, turnaround, &delay)) {
    return Status::InvalidArgument("time sync: stamps overflow int64 arithmetic");
  }
  if (round_trip < 0) {
    return Status::InvalidArgument("time sync: t4 " + std::to_string(t4_ns) + " before t1 " +
                                   std::to_string(t1_ns));
  }
  if (turnaround < 0) {
    return Status::InvalidArgument("time sync: t3 " + std::to_string(t3_ns) + " before t2 " +
                                   std::to_string(t2_ns));
  }
  // Clocks that run at slightly different rates can make a near-zero network
  // delay look negative by (drift) x (turnaround); more than that is bogus.
  const int64_t tolerance = 1000 + turnaround / 5000 + 2 * std::max<int64_t>(0, stamp_step_ns);
  if (delay < -tolerance) {
    return Status::InvalidArgument("time sync: round trip " + std::to_string(delay) +
                                   " ns is negative (turnaround longer than the whole exchange)");
  }
  sample->local_mid_ns = t1_ns + round_trip / 2;
  sample->offset_ns = sum / 2;
  sample->delay_ns = std::max<int64_t>(delay, 0);
  return Status::Ok();
}

// ---------------------------------------------------------------------------
// ClockOffsetEstimator

ClockOffsetEstimator::ClockOffsetEstimator(const ClockSyncOptions& options) : options_(options) {}

void ClockOffsetEstimator::Reset() {
  samples_.clear();
  pending_.clear();
}

ClockOffsetEstimator::Verdict ClockOffsetEstimator::AddSample(const TimeSyncSample& sample) {
  if (static_cast<int>(samples_.size()) >= options_.min_samples) {
    // Physically, a sample is within d / 2 of the true offset, and the fit
    // within d_min / 2 (+ its statistical error): further apart, one of them
    // is wrong. One outlier is held back; several in a row mean the
    // teammate's clock stepped (reboot, NTP step), so the fit restarts.
    const double residual =
        static_cast<double>(sample.offset_ns - base_offset_ns_) - OffsetAt(sample.local_mid_ns);
    const double allowed = 0.5 * static_cast<double>(sample.delay_ns) +
                           0.5 * static_cast<double>(min_delay_ns_) +
                           kOutlierSigmas * std::sqrt(VarianceAt(sample.local_mid_ns)) +
                           kOutlierSigmas * options_.timestamp_noise_s * kNsPerS;
    if (std::abs(residual) > allowed) {
      pending_.push_back(sample);
      if (static_cast<int>(pending_.size()) < options_.step_reset_samples) {
        return Verdict::kOutlier;
      }
      samples_.assign(pending_.begin(), pending_.end());
      pending_.clear();
      ++resets_;
      Fit();
      return Verdict::kStepReset;
    }
  }
  pending_.clear();
  samples_.push_back(sample);
  Fit();
  return Verdict::kAdded;
}

bool ClockOffsetEstimator::TrimWindow() {
  // Window: newest local time, then drop by count and age.
  while (static_cast<int>(samples_.size()) > options_.window_samples) samples_.pop_front();
  int64_t newest = std::numeric_limits<int64_t>::min();
  for (const TimeSyncSample& s : samples_) newest = std::max(newest, s.local_mid_ns);
  const int64_t window_ns = SecondsToNs(options_.window_s);
  samples_.erase(
      std::remove_if(samples_.begin(), samples_.end(),
                     [&](const TimeSyncSample& s) { return newest - s.local_mid_ns > window_ns; }),
      samples_.end());
  if (samples_.empty()) return false;
  base_time_ns_ = newest;
  base_offset_ns_ = samples_.back().offset_ns;
  min_delay_ns_ = std::numeric_limits<int64_t>::max();
  for (const TimeSyncSample& s : samples_) min_delay_ns_ = std::min(min_delay_ns_, s.delay_ns);
  return true;
}

std::vector<TimeSyncSample> ClockOffsetEstimator::SamplesToFit(double prior_info) const {
  // Exchanges that no offset explains (a fast lane, as netem's reorder: one
  // leg skipped the path delay) are left out (src/net/offset_outliers.h).
  std::vector<TimeSyncSample> used(samples_.begin(), samples_.end());
  if (used.size() >= static_cast<size_t>(kRobustFitMinSamples)) {
    internal::OffsetSamples window;
    window.floor_ns = options_.timestamp_noise_s * kNsPerS;
    window.prior_info = prior_info;
    for (const TimeSyncSample& s : samples_) {
      window.x.push_back(static_cast<double>(s.local_mid_ns - base_time_ns_) / kNsPerS);
      window.y.push_back(static_cast<double>(s.offset_ns - base_offset_ns_));
      window.round_trip.push_back(static_cast<double>(s.delay_ns));
    }
    const std::vector<double> outlier = internal::OffsetOutlierProbabilities(window);
    used.clear();
    for (size_t i = 0; i < samples_.size(); ++i) {
      if (outlier[i] < 0.5) used.push_back(samples_[i]);
    }
    if (used.size() < 3) used.assign(samples_.begin(), samples_.end());
  }
  return used;
}

void ClockOffsetEstimator::Fit() {
  if (!TrimWindow()) return;
  const double prior_b = options_.drift_prior_ppm * 1e3;  // [ns/s]
  const double prior_info = 1.0 / (prior_b * prior_b);
  const std::vector<TimeSyncSample> used = SamplesToFit(prior_info);
  const size_t n = used.size();
  const DelayStatistics delays = ComputeDelayStatistics(used, options_.timestamp_noise_s * kNsPerS);

  FitSamples samples;
  samples.xs.resize(n);
  samples.ys.resize(n);
  samples.excess.resize(n);
  samples.ws.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const TimeSyncSample& s = used[i];
    samples.xs[i] = static_cast<double>(s.local_mid_ns - base_time_ns_) / kNsPerS;    // [s], <= 0
    samples.ys[i] = static_cast<double>(s.offset_ns - base_offset_ns_);               // [ns]
    samples.excess[i] = 0.5 * static_cast<double>(s.delay_ns - delays.min_delay_ns);  // [ns]
    samples.ws[i] = 1.0 / (delays.s0 * delays.s0 + samples.excess[i] * samples.excess[i]);
  }
  const internal::WeightedLine line = FitRobustLine(&samples, delays, prior_info);
  a_ns_ = line.a;
  b_ns_per_s_ = line.b;
  cov_aa_ = line.caa;
  cov_ab_ = line.cab;
  cov_bb_ = line.cbb;
}

double ClockOffsetEstimator::OffsetAt(int64_t local_ns) const {
  return a_ns_ + b_ns_per_s_ * static_cast<double>(local_ns - base_time_ns_) / kNsPerS;
}

double ClockOffsetEstimator::VarianceAt(int64_t local_ns) const {
  const double dt = static_cast<double>(local_ns - base_time_ns_) / kNsPerS;
  return cov_aa_ + 2.0 * dt * cov_ab_ + dt * dt * cov_bb_;
}

ClockOffsetEstimate ClockOffsetEstimator::Estimate(int64_t now_ns) const {
  ClockOffsetEstimate e;
  if (samples_.empty()) return e;
  e.valid = true;
  e.num_samples = static_cast<int>(samples_.size());
  e.converged = e.num_samples >= options_.min_samples;
  e.offset_ns = base_offset_ns_ + std::llround(OffsetAt(now_ns));
  e.drift_ppm = b_ns_per_s_ * 1e-3;
  e.drift_std_ppm = std::sqrt(cov_bb_) * 1e-3;
  e.std_ns = std::sqrt(std::max(0.0, VarianceAt(now_ns)));
  e.min_delay_ns = min_delay_ns_;
  e.asymmetry_bound_ns = 0.5 * static_cast<double>(min_delay_ns_);
  if (!e.converged) e.std_ns = std::max(e.std_ns, e.asymmetry_bound_ns / std::sqrt(3.0));
  e.last_sample_ns = base_time_ns_;
  return e;
}

bool ClockOffsetEstimator::ToLocal(int64_t remote_ns, int64_t* local_ns) const {
  if (samples_.empty()) return false;
  // remote = local + offset(local), offset linear in local: solve for local.
  int64_t d = 0;
  if (!Sub(remote_ns, base_offset_ns_, &d) || !Sub(d, base_time_ns_, &d)) return false;
  const double u = (static_cast<double>(d) - a_ns_) / (1.0 + b_ns_per_s_ / kNsPerS);
  if (!(std::abs(u) < 0x1p62)) return false;
  return Add(base_time_ns_, std::llround(u), local_ns);
}

bool ClockOffsetEstimator::ToRemote(int64_t local_ns, int64_t* remote_ns) const {
  if (samples_.empty()) return false;
  int64_t dt = 0;
  if (!Sub(local_ns, base_time_ns_, &dt)) return false;
  const double offset = a_ns_ + b_ns_per_s_ * static_cast<double>(dt) / kNsPerS;
  if (!(std::abs(offset) < 0x1p62)) return false;
  int64_t shifted = 0;
  return Add(local_ns, base_offset_ns_, &shifted) && Add(shifted, std::llround(offset), remote_ns);
}

// ---------------------------------------------------------------------------
// ClockSync

ClockSync::ClockSync(int self_id, const ClockSyncOptions& options)
    : self_id_(self_id),
      options_(options),
      period_ns_(std::max<int64_t>(1, SecondsToNs(options.request_period_s))),
      settled_period_ns_(std::max<int64_t>(1, SecondsToNs(options.settled_request_period_s))),
      burst_period_ns_(std::max<int64_t>(1, SecondsToNs(options.burst_period_s))),
      timeout_ns_(SecondsToNs(options.response_timeout_s)) {}

Status ClockSync::Create(int self_id,
                         const ClockSyncOptions& options,
                         std::unique_ptr<ClockSync>* sync) {
  if (!IsValidDroneId(self_id)) {
    return Status::InvalidArgument("clock sync: drone id " + std::to_string(self_id) +
                                   " out of range 0.." + std::to_string(kMaxSwarmSize - 1));
  }
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument("clock_sync." + error);
  sync->reset(new ClockSync(self_id, options));
  return Status::Ok();
}

void ClockSync::AddTeammate(int teammate_id, int64_t now_ns) {
  if (!IsValidDroneId(teammate_id) || teammate_id == self_id_) return;
  auto [it, inserted] = teammates_.try_emplace(teammate_id, options_);
  if (inserted) {
    it->second.next_request_ns = now_ns;
    it->second.burst_remaining = options_.burst_requests;
  }
}

void ClockSync::RemoveTeammate(int teammate_id) { teammates_.erase(teammate_id); }

void ClockSync::ExpireRequests(int64_t now_ns, Teammate* teammate) const {
  while (!teammate->outstanding.empty() && now_ns - teammate->outstanding.front() > timeout_ns_) {
    teammate->outstanding.pop_front();
    ++teammate->stats.requests_timed_out;
  }
}

void ClockSync::NoteOwnState(int64_t stamp_ns) {
  if (!echo_mode()) return;
  own_stamps_.push_back(stamp_ns);
  if (own_stamps_.size() > kOwnStates) own_stamps_.pop_front();
}

void ClockSync::NoteTeammateState(const EgoStateMessage& state, int64_t arrival_ns) {
  auto it = teammates_.find(state.sender_id);
  if (it == teammates_.end() || state.send_delay_ns < 0) return;
  Teammate& teammate = it->second;
  if (echo_mode()) {
    teammate.state_to_echo = true;
    teammate.state_stamp_ns = state.stamp_ns;
    teammate.state_send_delay_ns = state.send_delay_ns;
    teammate.state_arrival_ns = arrival_ns;
  }
  int64_t t3 = 0;
  if (!Add(state.stamp_ns, state.send_delay_ns, &t3)) return;
  for (const StateEcho& echo : state.echoes) {
    if (echo.teammate_id != self_id_) continue;
    // The newest of our states with that reference (unique over 65 s).
    auto own = std::find_if(own_stamps_.rbegin(), own_stamps_.rend(), [&](int64_t stamp) {
      return StateEchoRef(stamp) == echo.stamp_ref;
    });
    int64_t t1 = 0;
    if (own == own_stamps_.rend() || !Add(*own, echo.send_delay_ns, &t1)) {
      ++teammate.stats.echoes_unmatched;
      continue;
    }
    if (AddExchange(t1, echo.arrival_ns, t3, arrival_ns, kSyncDelayStepNs, &teammate)) {
      ++teammate.stats.echoes_matched;
    }
  }
  if (state.offset_report && state.offset_report->teammate_id == self_id_) {
    NoteReport(*state.offset_report, state.stamp_ns, &teammate);
  }
}

bool ClockSync::Settled(const Teammate& teammate, int64_t now_ns) const {
  if (options_.settled_std_s <= 0.0) return false;  // 0 = never settled
  const ClockOffsetEstimate e = teammate.estimator.Estimate(now_ns);
  return e.converged && e.std_ns <= options_.settled_std_s * 1e9;
}

void ClockSync::EchoesFor(int64_t now_ns, int max_echoes, EchoSelection selection,
                          std::vector<StateEcho>* echoes) {
  const int room = std::min(max_echoes, options_.max_echoes_per_state -
                                            static_cast<int>(echoes->size()));
  if (!echo_mode() || room <= 0) return;
  const int64_t max_age_ns = SecondsToNs(options_.max_echo_age_s);
  const int64_t period_ns = SecondsToNs(options_.echo_period_s);
  const int64_t unsettled_period_ns = SecondsToNs(options_.unsettled_echo_period_s);
  // (settled, echo order, id): unsettled first, then the least recently echoed.
  std::vector<std::tuple<bool, uint64_t, int>> due;
  for (const auto& [id, teammate] : teammates_) {
    if (!teammate.state_to_echo) continue;
    const int64_t age_ns = now_ns - teammate.state_arrival_ns;
    if (age_ns < 0 || age_ns > max_age_ns) continue;
    const bool settled = Settled(teammate, now_ns);
    const bool selected =
        selection == EchoSelection::kAll || (selection == EchoSelection::kUnsettled && !settled) ||
        teammate.estimator.num_samples() < options_.min_samples;
    if (selected) {
      const int64_t spacing_ns = settled ? period_ns : unsettled_period_ns;
      if (teammate.last_echo_ns == std::numeric_limits<int64_t>::min() ||
          now_ns - teammate.last_echo_ns >= spacing_ns) {
        due.emplace_back(settled, teammate.echo_order, id);
      }
    }
  }
  std::sort(due.begin(), due.end());
  if (due.size() > static_cast<size_t>(room)) due.resize(static_cast<size_t>(room));
  for (const auto& [settled, last, id] : due) {
    (void)settled;
    (void)last;
    Teammate& teammate = teammates_.at(id);
    StateEcho echo;
    echo.teammate_id = id;
    echo.stamp_ref = StateEchoRef(teammate.state_stamp_ns);
    echo.send_delay_ns = teammate.state_send_delay_ns;
    echo.arrival_ns = teammate.state_arrival_ns;
    echoes->push_back(echo);
    teammate.state_to_echo = false;
    teammate.last_echo_ns = now_ns;
    teammate.echo_order = ++echoes_made_;
    ++teammate.stats.echoes_sent;
  }
}

bool ClockSync::AddExchange(int64_t t1_ns, int64_t t2_ns, int64_t t3_ns, int64_t t4_ns,
                            int64_t stamp_step_ns, Teammate* teammate) {
  TimeSyncSample sample;
  if (!ReduceTimeSyncExchange(t1_ns, t2_ns, t3_ns, t4_ns, &sample, stamp_step_ns).ok()) {
    ++teammate->stats.exchanges_invalid;
    return false;
  }
  switch (teammate->estimator.AddSample(sample)) {
    case ClockOffsetEstimator::Verdict::kAdded:
      break;
    case ClockOffsetEstimator::Verdict::kOutlier:
      ++teammate->stats.outliers;
      break;
    case ClockOffsetEstimator::Verdict::kStepReset:
      ++teammate->stats.outliers;
      ++teammate->stats.resets;
      teammate->burst_remaining = options_.burst_requests;
      break;
  }
  return true;
}

void ClockSync::DueRequests(int64_t now_ns, std::vector<TimeSyncMessage>* requests) {
  if (echo_mode()) return;
  for (auto& [id, teammate] : teammates_) {
    ExpireRequests(now_ns, &teammate);
    if (teammate.next_request_ns > now_ns) continue;
    // Burst first; then the regular period, or the slow one while the offset
    // extrapolated to the end of the slow period is known well enough (its
    // std grows with the drift's uncertainty, so a teammate whose requests go
    // unanswered or whose drift is not known yet is polled fast).
    int64_t spacing = teammate.burst_remaining > 0 ? burst_period_ns_ : period_ns_;
    if (teammate.burst_remaining == 0 && options_.settled_std_s > 0.0) {
      const ClockOffsetEstimate e = teammate.estimator.Estimate(now_ns + settled_period_ns_);
      if (e.converged && e.std_ns <= options_.settled_std_s * 1e9) spacing = settled_period_ns_;
    }
    teammate.burst_remaining = std::max(0, teammate.burst_remaining - 1);
    // Regular spacing; after a pause (no calls for a while) no catch-up burst.
    teammate.next_request_ns += spacing;
    if (teammate.next_request_ns <= now_ns) teammate.next_request_ns = now_ns + spacing;
    if (static_cast<int>(teammate.outstanding.size()) >= options_.max_outstanding_requests) {
      teammate.outstanding.pop_front();
      ++teammate.stats.requests_timed_out;
    }
    teammate.outstanding.push_back(now_ns);
    ++teammate.stats.requests_sent;
    TimeSyncMessage request;
    request.sender_id = self_id_;
    request.target_id = id;
    request.is_response = false;
    request.t1_ns = now_ns;
    requests->push_back(request);
  }
}

int64_t ClockSync::NextRequestNs() const {
  int64_t next = std::numeric_limits<int64_t>::max();
  if (echo_mode()) return next;
  for (const auto& [id, teammate] : teammates_) {
    (void)id;
    next = std::min(next, teammate.next_request_ns);
  }
  return next;
}

bool ClockSync::HandleMessage(const TimeSyncMessage& message,
                              int64_t arrival_ns,
                              int64_t reply_ns,
                              TimeSyncMessage* reply) {
  if (message.target_id != self_id_ || message.sender_id == self_id_) return false;
  if (!message.is_response) {
    reply->sender_id = self_id_;
    reply->target_id = message.sender_id;
    reply->is_response = true;
    reply->t1_ns = message.t1_ns;
    reply->t2_ns = arrival_ns;
    reply->t3_ns = std::max(reply_ns, arrival_ns);
    ++requests_answered_;
    return true;
  }
  auto it = teammates_.find(message.sender_id);
  if (it == teammates_.end()) return false;
  Teammate& teammate = it->second;
  ExpireRequests(arrival_ns, &teammate);
  auto match = std::find(teammate.outstanding.begin(), teammate.outstanding.end(), message.t1_ns);
  if (match == teammate.outstanding.end()) {
    ++teammate.stats.responses_unmatched;
    return false;
  }
  teammate.outstanding.erase(match);
  if (AddExchange(message.t1_ns, message.t2_ns, message.t3_ns, arrival_ns, 0, &teammate)) {
    ++teammate.stats.responses_matched;
  }
  return false;
}

ClockSyncStats ClockSync::Stats(int teammate_id) const {
  auto it = teammates_.find(teammate_id);
  return it == teammates_.end() ? ClockSyncStats() : it->second.stats;
}

std::string FormatClockOffsets(const ClockSync& sync, int64_t now_ns,
                               const std::vector<std::string>& names, const std::string& indent) {
  std::string text;
  for (int j = 0; j < kMaxSwarmSize; ++j) {
    if (!sync.HasTeammate(j)) continue;
    const ClockOffsetEstimate e = sync.Estimate(j, now_ns);
    if (!e.valid) continue;
    const ClockSyncStats st = sync.Stats(j);
    const std::string name =
        static_cast<size_t>(j) < names.size() ? names[static_cast<size_t>(j)] : "id" + std::to_string(j);
    char line[320];
    std::snprintf(line, sizeof(line),
                  "clock of %s: offset %+.3f ms (std %.3f ms, drift %+.1f ppm), %d exchanges "
                  "(%llu of its echoes, %llu responses), %llu requests, %llu timed out, "
                  "its report weighs %.2f (%llu used, %llu rejected)\n",
                  name.c_str(), 1e-6 * static_cast<double>(e.offset_ns), 1e-6 * e.std_ns,
                  e.drift_ppm, e.num_samples, static_cast<unsigned long long>(st.echoes_matched),
                  static_cast<unsigned long long>(st.responses_matched),
                  static_cast<unsigned long long>(st.requests_sent),
                  static_cast<unsigned long long>(st.requests_timed_out), e.report_weight,
                  static_cast<unsigned long long>(st.reports_used),
                  static_cast<unsigned long long>(st.reports_rejected));
    text += indent + line;
  }
  return text;
}

}  // namespace swarmlio::net
