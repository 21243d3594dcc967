// Clock synchronisation between drones: a per-teammate estimate of the offset
// of the teammate's clock relative to this drone's clock, from NTP-style
// four-timestamp exchanges (TimeSyncMessage), and the scheduler that sends the
// requests and matches the responses. Math, options and measured accuracy:
// docs/network.md, "Clock synchronisation".
//
//   std::unique_ptr<net::ClockSync> sync;
//   SWARMLIO_RETURN_IF_ERROR(net::ClockSync::Create(self_id, options, &sync));
//   sync->AddTeammate(j, now_ns);          // when j is first heard
//   sync->DueRequests(now_ns, &requests);  // send each one now
//   // For each received TimeSync m:
//   if (sync->HandleMessage(m, arrival_ns, now_ns, &reply)) {
//     channel.Send(now_ns, reply.target_id, reply);
//   }
//   // j's stamp on our clock:
//   if (sync->ToLocal(j, ego_state.stamp_ns, &t_local)) ...
//
// offset = remote clock - local clock at the same instant. One exchange
// (requester stamps t1 and t4 on its clock, responder t2 and t3 on its clock):
//   offset sample  o = ((t2 - t1) + (t3 - t4)) / 2 = offset + (d_fwd - d_back) / 2
//   round trip     d = (t4 - t1) - (t3 - t2)        = d_fwd + d_back
// so a sample is wrong by half the difference of the two one-way delays: at
// most d / 2, and by about (d - d_min) / 2 when extra queueing hit one leg.
// The estimator fits offset(t) = a + b (t - t_ref) (b: relative drift) by
// robust weighted least squares over a sliding window with a zero-mean prior
// on the drift: sample i has variance sr^2 + ((d_i - d_min) / 2)^2 (sr: the
// noise of an undelayed exchange, from the round-trip spread and the
// residuals of the least-delayed half) and a Huber weight. A constant path
// asymmetry (d_fwd != d_back on average) biases every sample alike; no
// two-way exchange can see it, and the estimate is off by half of it (at most
// d_min / 2, reported as asymmetry_bound_ns). Details and measured accuracy:
// docs/network.md.
//
// Nothing here reads a clock: every time is an argument on this drone's clock
// (int64 ns, docs/conventions.md). One thread uses a ClockSync at a time.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/net/messages.h"

namespace swarmlio::net {

/// How the four timestamps of an exchange travel.
enum class ClockExchange {
  kStateEcho,  // in the EgoState broadcasts: each state carries its send delay and echoes
               // of teammates' states (wire version 5; no extra packets, cost independent of N)
  kRequests,   // TimeSync request/response packets per teammate (2 (N-1) packets per period)
};

}  // namespace swarmlio::net

namespace swarmlio::config {
template <>
struct EnumTraits<net::ClockExchange> {
  static constexpr std::array<std::pair<net::ClockExchange, const char*>, 2> kNames{{
      {net::ClockExchange::kStateEcho, "state_echo"},
      {net::ClockExchange::kRequests, "requests"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::net {

/// YAML section `clock_sync`.
struct ClockSyncOptions {
  ClockExchange exchange = ClockExchange::kStateEcho;
  double echo_period_s = 0.2;        // state echo: each teammate's state echoed at most this
                                     // often [s] ...
  double unsettled_echo_period_s = 0.1;  // ... and this often while the offset to it is not
                                         // settled (settled_std_s), e.g. after its restart [s]
  int max_echoes_per_state = 2;      // state echo: echoes per EgoState (bounds the bytes for
                                     // any swarm size)
  double max_echo_age_s = 0.4;       // state echo: a teammate state older than this when our
                                     // state is made is not echoed [s]
  double request_period_s = 1.0;     // requests: one request per teammate per period [s]
  double settled_request_period_s = 10.0;  // ... once the offset std is below settled_std_s [s]
  double settled_std_s = 0.5e-3;           // (at the end of that period; NTP's poll interval
                                           // growth; 0 = never settle) [s]
  int burst_requests = 8;            // the first requests to a teammate (and after its
  double burst_period_s = 0.25;      // clock stepped) come this fast [s], as NTP's iburst
  double response_timeout_s = 1.0;   // a response later than this is dropped [s]
  int max_outstanding_requests = 8;  // per teammate; the oldest is dropped beyond it
  int window_samples = 1024;         // samples kept per teammate
  double window_s = 1800.0;          // samples older than this (local clock) are dropped [s]
  int min_samples = 4;               // the estimate is "converged" from this many samples on
  double timestamp_noise_s = 50e-6;  // floor of a sample's standard deviation [s]
  double drift_prior_ppm = 100.0;    // prior std of the relative clock drift [ppm]
  int step_reset_samples = 3;        // this many consecutive samples that contradict the fit:
                                     // the teammate's clock stepped, restart from them
  double report_period_s = 1.0;      // state echo: our estimate of a teammate's offset goes
                                     // to it at most this often, for it to fuse with its own
                                     // (0 = never; reports received are still used) [s]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("exchange", exchange,
      FieldSpec::Doc("state_echo (timestamps in the state broadcasts) or requests (TimeSync "
                     "packets per teammate)"));
    config::VisitExperimental(v, [&](auto& x) {
      x("echo_period_s", echo_period_s,
        FieldSpec::InRange(0.01, 3600.0, "s", "state echo: a teammate's state echoed at most this often"));
      x("unsettled_echo_period_s", unsettled_echo_period_s,
        FieldSpec::InRange(0.01, 3600.0, "s",
                           "state echo: ... and this often while the offset is not settled"));
      x("max_echoes_per_state", max_echoes_per_state,
        FieldSpec::InRange(1, EgoStateMessage::kMaxEchoes, "", "state echo: echoes per EgoState"));
      x("max_echo_age_s", max_echo_age_s,
        FieldSpec::InRange(0.001, 0.5, "s", "state echo: oldest teammate state that is echoed"));
      x("request_period_s", request_period_s,
        FieldSpec::Positive("s", "interval between requests to one teammate").WithMax(3600.0));
      x("settled_request_period_s", settled_request_period_s,
        FieldSpec::Positive("s", "interval between requests once the offset is settled").WithMax(3600.0));
      x("settled_std_s", settled_std_s,
        FieldSpec::InRange(0.0, 1.0, "s", "offset std below which requests slow down (0 = never)"));
      x("burst_requests", burst_requests,
        FieldSpec::InRange(0, 64, "", "requests at burst_period_s when a teammate appears"));
      x("burst_period_s", burst_period_s,
        FieldSpec::Positive("s", "interval between the burst requests").WithMax(3600.0));
      x("response_timeout_s", response_timeout_s,
        FieldSpec::Positive("s", "responses arriving later are dropped").WithMax(60.0));
      x("max_outstanding_requests", max_outstanding_requests,
        FieldSpec::InRange(1, 64, "", "requests in flight per teammate"));
      x("window_samples", window_samples,
        FieldSpec::InRange(2, 4096, "", "exchanges kept per teammate for the fit"));
      x("window_s", window_s,
        FieldSpec::Positive("s", "exchanges older than this are dropped").WithMax(86400.0));
      x("min_samples", min_samples,
        FieldSpec::InRange(1, 4096, "", "exchanges before the estimate counts as converged"));
      x("timestamp_noise_s", timestamp_noise_s,
        FieldSpec::Positive("s", "floor of one exchange's offset std (stamping noise)").WithMax(1.0));
      x("drift_prior_ppm", drift_prior_ppm,
        FieldSpec::Positive("ppm", "prior std of the relative drift of two clocks").WithMax(1e5));
      x("step_reset_samples", step_reset_samples,
        FieldSpec::InRange(1, 64, "", "consecutive contradicting exchanges that restart the fit"));
      x("report_period_s", report_period_s,
        FieldSpec::InRange(0.0, 3600.0, "s",
                           "our offset estimate sent to each teammate at most this often (0 = never)"));
    });
  }

  std::string Validate() const;
};

/// One exchange reduced to what the fit uses.
struct TimeSyncSample {
  int64_t local_mid_ns = 0;  // t1 + (t4 - t1) / 2, local clock [ns]
  int64_t offset_ns = 0;     // ((t2 - t1) + (t3 - t4)) / 2, remote - local [ns]
  int64_t delay_ns = 0;      // (t4 - t1) - (t3 - t2), round trip on the network [ns]
};

/// Reduces an exchange. InvalidArgument when t4 < t1, t3 < t2, the round trip
/// is negative beyond the drift tolerance (2e-4 of t3 - t2, plus 1 us, plus
/// 2 `stamp_step_ns` for stamps that travel rounded to that step), or an
/// intermediate value overflows int64.
Status ReduceTimeSyncExchange(int64_t t1_ns, int64_t t2_ns, int64_t t3_ns, int64_t t4_ns,
                              TimeSyncSample* sample, int64_t stamp_step_ns = 0);

/// The offset of one teammate's clock at a query time.
struct ClockOffsetEstimate {
  bool valid = false;      // at least one exchange
  bool converged = false;  // at least min_samples exchanges in the window
  int64_t offset_ns = 0;   // remote - local at the query time [ns]
  double drift_ppm = 0.0;  // d(offset)/dt [ppm]
  double std_ns = 0.0;     // 1-sigma of offset_ns assuming symmetric paths; before
                           // convergence at least asymmetry_bound_ns / sqrt(3) [ns]
  double drift_std_ppm = 0.0;
  double asymmetry_bound_ns = 0.0;  // |bias| from path asymmetry is at most this: d_min / 2 [ns]
  int64_t min_delay_ns = 0;         // smallest round trip in the window [ns]
  int num_samples = 0;              // exchanges in the window
  int64_t last_sample_ns = 0;       // local time of the newest exchange [ns]
  double report_weight = 0.0;       // ClockSync only: the weight of the teammate's own
                                    // estimate (its report) in offset_ns; 0 = ours alone
};

/// Offset (and drift) of one teammate's clock from its exchanges.
class ClockOffsetEstimator {
 public:
  enum class Verdict {
    kAdded,      // used
    kOutlier,    // contradicts the fit beyond what its delay allows; held back
    kStepReset,  // step_reset_samples outliers in a row: fit restarted from them
  };

  /// From this many exchanges in the window on, those that no offset
  /// explains are found and left out (src/net/offset_outliers.h); fewer
  /// cannot tell them apart.
  static constexpr int kRobustFitMinSamples = 20;

  /// `options` must satisfy Validate().
  explicit ClockOffsetEstimator(const ClockSyncOptions& options);

  Verdict AddSample(const TimeSyncSample& sample);
  void Reset();

  /// The estimate at local time `now_ns` (the fit is extrapolated with its drift).
  ClockOffsetEstimate Estimate(int64_t now_ns) const;
  /// A stamp on the teammate's clock mapped to this drone's clock (false
  /// before the first exchange or on overflow).
  bool ToLocal(int64_t remote_ns, int64_t* local_ns) const;
  /// The inverse of ToLocal.
  bool ToRemote(int64_t local_ns, int64_t* remote_ns) const;

  int num_samples() const { return static_cast<int>(samples_.size()); }
  uint64_t resets() const { return resets_; }

 private:
  // Drops samples beyond the window (count, age); false when none is left,
  // else sets the base time and offset (newest sample) and min_delay_ns_.
  bool TrimWindow();
  // The window's samples the fit uses: all, or (kRobustFitMinSamples and
  // more) those the outlier model does not reject.
  std::vector<TimeSyncSample> SamplesToFit(double prior_info) const;
  void Fit();
  double OffsetAt(int64_t local_ns) const;  // relative to base_offset_ns_ [ns]
  double VarianceAt(int64_t local_ns) const;

  ClockSyncOptions options_;
  std::deque<TimeSyncSample> samples_;   // arrival order
  std::vector<TimeSyncSample> pending_;  // consecutive outliers
  uint64_t resets_ = 0;
  // offset(t) = base_offset_ns_ + a_ns_ + b_ns_per_s_ * (t - base_time_ns_) * 1e-9
  int64_t base_time_ns_ = 0;
  int64_t base_offset_ns_ = 0;
  double a_ns_ = 0.0;
  double b_ns_per_s_ = 0.0;
  double cov_aa_ = 0.0, cov_ab_ = 0.0, cov_bb_ = 0.0;  // [ns^2], [ns^2/s], [ns^2/s^2]
  int64_t min_delay_ns_ = 0;
};

/// Counters of one teammate.
struct ClockSyncStats {
  uint64_t echoes_sent = 0;          // its states echoed in ours
  uint64_t echoes_matched = 0;       // its echoes of our states that became a sample
  uint64_t echoes_unmatched = 0;     // echoes of a state we do not remember sending
  uint64_t requests_sent = 0;
  uint64_t requests_timed_out = 0;   // no response within response_timeout_s, or displaced
  uint64_t responses_matched = 0;    // became a sample
  uint64_t responses_unmatched = 0;  // unknown t1: late, duplicated or never sent
  uint64_t exchanges_invalid = 0;    // stamps ReduceTimeSyncExchange rejects
  uint64_t outliers = 0;             // samples held back as contradicting the fit
  uint64_t resets = 0;               // fit restarts (clock steps)
  uint64_t reports_sent = 0;         // our estimates of its offset sent to it
  uint64_t reports_used = 0;         // its estimates of ours fused into ours
  uint64_t reports_rejected = 0;     // ... received but unusable: ours not converged, or the
                                     // two disagree beyond 5 sigma
};

/// One drone's clock synchronisation with all its teammates.
class ClockSync {
 public:
  /// InvalidArgument for an invalid id or options (message names the key).
  static Status Create(int self_id,
                       const ClockSyncOptions& options,
                       std::unique_ptr<ClockSync>* sync);

  int self_id() const { return self_id_; }

  /// Starts synchronising with `teammate_id` (no-op if known, ignored if
  /// invalid or self); its first request is due at `now_ns`.
  void AddTeammate(int teammate_id, int64_t now_ns);
  /// Forgets the teammate's clock (it rebooted: new session_start_ns).
  void RemoveTeammate(int teammate_id);
  bool HasTeammate(int teammate_id) const { return teammates_.count(teammate_id) != 0; }

  /// State echo (exchange = state_echo; no-ops otherwise). Our state stamped
  /// `stamp_ns` is going out (a teammate's echo names it by StateEchoRef).
  void NoteOwnState(int64_t stamp_ns);
  /// Teammate j's state arrived at `arrival_ns` (j must be added first): kept
  /// to be echoed back, and j's echo of one of our states becomes a sample
  /// (t1 = our stamp + the echoed send delay, t2 = the echo's arrival, t3 =
  /// j's stamp + its send delay, t4 = arrival_ns). Bad input never fails.
  void NoteTeammateState(const EgoStateMessage& state, int64_t arrival_ns);
  /// The echoes for our state made at `now_ns`: teammates whose newest state
  /// is not echoed yet, arrived within max_echo_age_s and was last echoed
  /// echo_period_s ago or earlier; the least recently echoed first, at most
  /// max_echoes_per_state. A teammate whose offset (this drone's estimate;
  /// the link is the same both ways, so the teammate's estimate of ours is
  /// about as good) is not settled (settled_std_s) is due after
  /// unsettled_echo_period_s instead, and comes first.
  void EchoesFor(int64_t now_ns, std::vector<StateEcho>* echoes) {
    EchoesFor(now_ns, options_.max_echoes_per_state, EchoSelection::kAll, echoes);
  }
  /// The same, at most max_echoes (what the sender's byte budget affords; the
  /// others stay due), and only teammates whose offset is: kUnconverged,
  /// estimated from fewer than min_samples exchanges (unknown clocks);
  /// kUnsettled, not settled (settled_std_s); kAll, any. A sender ranks them
  /// differently against its other content. The echoes already in *echoes
  /// count against max_echoes_per_state.
  enum class EchoSelection { kAll, kUnsettled, kUnconverged };
  void EchoesFor(int64_t now_ns, int max_echoes, EchoSelection selection,
                 std::vector<StateEcho>* echoes);

  /// Both ends of a pair (state echo): the report for our state made at
  /// `now_ns`, if one is due: our own estimate (not fused) of the offset of
  /// a teammate whose estimate is converged with std <= 12.7 ms and whose
  /// last report is report_period_s old, the least recently reported first.
  /// Recorded as sent.
  bool ReportFor(int64_t now_ns, ClockOffsetReport* report);

  /// Requests only (none with exchange = state_echo):
  /// appends the requests due at `now_ns` (at most one per teammate, t1 =
  /// now_ns) and records them as sent: send each one at `now_ns`.
  void DueRequests(int64_t now_ns, std::vector<TimeSyncMessage>* requests);
  /// When the next request is due (INT64_MAX without teammates or requests).
  int64_t NextRequestNs() const;

  /// Handles an authenticated TimeSync message (ReceivedMessage::message)
  /// that arrived at `arrival_ns`. A request addressed to this drone yields
  /// the response in `*reply` (t2 = arrival_ns, t3 = reply_ns; send it at
  /// reply_ns >= arrival_ns) and returns true. A response to one of our
  /// outstanding requests becomes a sample (t4 = arrival_ns). Anything else
  /// is counted and ignored; bad input never fails.
  bool HandleMessage(const TimeSyncMessage& message,
                     int64_t arrival_ns,
                     int64_t reply_ns,
                     TimeSyncMessage* reply);

  /// The teammate's offset at local time `now_ns` (valid = false if unknown):
  /// our estimate, fused with the teammate's latest report of its own
  /// estimate of ours when there is one (docs/network.md "Both ends of a
  /// pair"; report_weight says how much it counts).
  ClockOffsetEstimate Estimate(int teammate_id, int64_t now_ns) const;
  /// The teammate's stamp on this drone's clock with that estimate (false if
  /// not estimated yet).
  bool ToLocal(int teammate_id, int64_t remote_ns, int64_t* local_ns) const;
  /// Counters of one teammate (zeros if unknown).
  ClockSyncStats Stats(int teammate_id) const;
  /// Requests from teammates that this drone answered.
  uint64_t requests_answered() const { return requests_answered_; }

 private:
  struct Teammate {
    explicit Teammate(const ClockSyncOptions& options) : estimator(options) {}
    int64_t next_request_ns = 0;
    int burst_remaining = 0;
    std::deque<int64_t> outstanding;  // t1 of requests in flight, ascending
    // State echo: its newest state (to echo back) and when we last echoed one.
    bool state_to_echo = false;
    int64_t state_stamp_ns = 0;
    int64_t state_send_delay_ns = 0;
    int64_t state_arrival_ns = 0;
    int64_t last_echo_ns = std::numeric_limits<int64_t>::min();
    uint64_t echo_order = 0;  // echoes_made_ at its last echo (0 = never): rotation order
    // Its report of its estimate of our offset, turned into one of its offset:
    bool have_report = false;
    int64_t report_local_ns = 0;   // our time of the reporting state's stamp [ns]
    int64_t report_offset_ns = 0;  // its offset (- its estimate of ours) [ns]
    double report_var_ns2 = 0.0;
    uint64_t report_resets = 0;    // estimator.resets() when it came: a reset drops it
    // Our reports of its offset.
    int64_t last_report_ns = std::numeric_limits<int64_t>::min();
    uint64_t report_order = 0;  // reports_made_ at our last report to it (0 = never)
    ClockOffsetEstimator estimator;
    ClockSyncStats stats;
  };
  ClockSync(int self_id, const ClockSyncOptions& options);
  void ExpireRequests(int64_t now_ns, Teammate* teammate) const;
  /// Adds one exchange's sample; false if its stamps are invalid.
  bool AddExchange(int64_t t1_ns, int64_t t2_ns, int64_t t3_ns, int64_t t4_ns,
                   int64_t stamp_step_ns, Teammate* teammate);
  bool echo_mode() const { return options_.exchange == ClockExchange::kStateEcho; }
  /// The offset to the teammate at now_ns is converged with std <= settled_std_s.
  bool Settled(const Teammate& teammate, int64_t now_ns) const;
  /// A teammate's report of its estimate of our offset (state echo).
  void NoteReport(const ClockOffsetReport& report, int64_t stamp_ns, Teammate* teammate);
  /// Our estimate fused with the teammate's report (clock_sync_reports.cc).
  ClockOffsetEstimate Fused(const Teammate& teammate, int64_t now_ns) const;

  int self_id_;
  ClockSyncOptions options_;
  int64_t period_ns_;
  int64_t settled_period_ns_;
  int64_t burst_period_ns_;
  int64_t timeout_ns_;
  std::map<int, Teammate> teammates_;  // ordered: deterministic request order
  std::deque<int64_t> own_stamps_;     // our last kOwnStates state stamps (state echo)
  uint64_t echoes_made_ = 0;
  uint64_t reports_made_ = 0;
  uint64_t requests_answered_ = 0;
};

/// One line per synchronised teammate at local time `now_ns`, for the
/// tools' summaries: "clock of <name>: offset +x.xxx ms (std ..., drift ...),
/// N exchanges, R requests, T timed out". `names[id]` names a teammate
/// ("id<N>" beyond it); each line starts with `indent`.
std::string FormatClockOffsets(const ClockSync& sync, int64_t now_ns,
                               const std::vector<std::string>& names, const std::string& indent);

}  // namespace swarmlio::net
