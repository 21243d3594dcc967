// Clock synchronisation end to end: the offset estimate of drones with
// offset and drifting clocks that exchange TimeSync messages (exchange =
// requests) or EgoState broadcasts with echoes (exchange = state_echo)
// through the codec and the seeded simulated network.
#include "swarmlio/net/clock_sync.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/net/message_channel.h"
#include "swarmlio/net/simulated_network.h"
#include "swarmlio/net/clock_sync_simulation.h"
#include "tests/net/net_test_util.h"

namespace swarmlio::net {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kS = 1'000'000'000;

using CaseFigures = ClockSyncFigures;

/// The simulation of swarmlio/net/clock_sync_simulation.h, failing the test
/// on any error.
class SyncSimulation {
 public:
  SyncSimulation(const NetworkOptions& network_options, std::vector<SimulatedClock> clocks,
                 const ClockSyncOptions& sync_options) {
    const Status s = ClockSyncSimulation::Create(network_options, std::move(clocks),
                                                      sync_options, 1 * kMs, &sim_);
    EXPECT_TRUE(s.ok()) << s.message();
  }
  void RunUntil(int64_t end_ns) {
    const Status s = sim_->RunUntil(end_ns);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  ClockOffsetEstimate Estimate(int i, int j) const { return sim_->Estimate(i, j); }
  double Error(int i, int j) const { return sim_->Error(i, j); }
  const ClockSync& sync(int i) const { return sim_->sync(i); }
  ClockSync& mutable_sync(int i) { return sim_->mutable_sync(i); }
  const SimulatedClock& clock(int i) const { return sim_->clock(i); }
  int64_t now_ns() const { return sim_->now_ns(); }

 private:
  std::unique_ptr<ClockSyncSimulation> sim_;
};

/// The TimeSync request/response scheme (the figures of docs/network.md §9).
ClockSyncOptions Requests() {
  ClockSyncOptions options;
  options.exchange = ClockExchange::kRequests;
  return options;
}

CaseFigures RunCase(const LinkOptions& link,
                    const ClockSyncOptions& options,
                    int seeds,
                    int end_s,
                    int settle_s,
                    const std::vector<SimulatedClock>& clocks = SwarmClocks()) {
  CaseFigures f;
  const Status s = RunClockSyncCase(link, options, seeds, end_s, settle_s, clocks, &f);
  EXPECT_TRUE(s.ok()) << s.message();
  return f;
}

void Print(const char* name, const CaseFigures& f, int settle_s) {
  std::printf(
      "[ figures  ] %s: from %d s max %.3f ms, rms %.3f ms, |e| <= 3 std in %.1f %%, "
      "max |e|/std %.2f; all pairs within 2 ms from t = %.0f s\n",
      name, settle_s, f.max_abs_ms, f.rms_ms, 100.0 * f.within_3_sigma, f.max_normalised,
      f.within_2ms_from_s);
}

// ---------------------------------------------------------------------------
// Exchange arithmetic

TEST(ClockSyncSimulation, NominalLinkWithinTwoMillisecondsAfterTheFirstExchanges) {
  const CaseFigures f = RunCase(LinkOptions(), Requests(), 5, 120, 2);
  Print("5 ms +- 1 ms, 1 Hz, every 10 s once settled", f, 2);
  EXPECT_LT(f.max_abs_ms, 2.0);
  EXPECT_LT(f.rms_ms, 0.5);
  EXPECT_LE(f.within_2ms_from_s, 2.0);
  EXPECT_GE(f.within_3_sigma, 0.97);
}

/// netem's "loss 30% delay 200ms 1ms reorder": a fixed path delay with small
/// jitter, and some packets held back (a one-sided queueing tail).
LinkOptions LossyDelayedLink() {
  LinkOptions link;
  link.latency_mean_s = 0.2;
  link.jitter_std_s = 0.001;
  link.loss_probability = 0.3;
  link.reorder_probability = 0.2;
  link.reorder_delay_max_s = 0.05;
  return link;
}

TEST(ClockSyncSimulation, ThirtyPercentLossAndTwoHundredMillisecondDelay) {
  const CaseFigures f = RunCase(LossyDelayedLink(), Requests(), 10, 300, 10);
  Print("30 % loss, 200 ms +- 1 ms, 20 % held back U(0, 50 ms), 1 Hz, every 10 s once settled", f, 10);
  EXPECT_LT(f.rms_ms, 1.0);
  EXPECT_LT(f.within_2ms_from_s, 60.0);
  EXPECT_GE(f.within_3_sigma, 0.97);
}

TEST(ClockSyncSimulation, SymmetricJitterNeedsManyExchanges) {
  // 200 ms +- 20 ms on each leg: one exchange's error is (d_fwd - d_back) / 2,
  // std 20 / sqrt(2) = 14 ms, whatever its round trip (for a symmetric
  // jitter the two are independent), so no filter beats averaging: the fit's
  // error is about 2 x 14 ms / sqrt(N) after N exchanges (offset and drift
  // fitted), and 2 ms needs hundreds of exchanges. The estimator must say so
  // in its uncertainty and reach the bound.
  LinkOptions link;
  link.latency_mean_s = 0.2;
  link.jitter_std_s = 0.02;
  link.loss_probability = 0.3;
  const CaseFigures at_1hz = RunCase(link, Requests(), 5, 120, 10);
  Print("30 % loss, 200 ms +- 20 ms, 1 Hz, first 120 s", at_1hz, 10);
  EXPECT_GE(at_1hz.within_3_sigma, 0.97);
  EXPECT_LT(at_1hz.rms_ms, 6.0);
  ClockSyncOptions fast = Requests();
  fast.request_period_s = 0.2;
  const CaseFigures at_5hz = RunCase(link, fast, 3, 900, 600);
  Print("30 % loss, 200 ms +- 20 ms, 5 Hz, 600-900 s", at_5hz, 600);
  EXPECT_GE(at_5hz.within_3_sigma, 0.97);
  EXPECT_LT(at_5hz.rms_ms, 1.0);
  EXPECT_LT(at_5hz.max_abs_ms, 3.0);
}

/// 0 -> 1 takes 10 ms, 1 -> 0 takes 50 ms; the other links 5 ms both ways.
NetworkOptions AsymmetricNetwork() {
  NetworkOptions network;
  network.seed = 3;
  LinkOverride forward, backward;
  forward.from_id = 0;
  forward.to_id = 1;
  forward.link.latency_mean_s = 0.010;
  backward.from_id = 1;
  backward.to_id = 0;
  backward.link.latency_mean_s = 0.050;
  network.links = {forward, backward};
  return network;
}

TEST(ClockSyncSimulation, AsymmetricPathIsBiasedByHalfTheAsymmetry) {
  const NetworkOptions network = AsymmetricNetwork();
  SyncSimulation sim(network, SwarmClocks(), Requests());
  sim.RunUntil(60 * kS);
  // Drone 0 asks 1: out 10 ms, back 50 ms: (10 - 50) / 2 = -20 ms. Drone 1
  // asking 0 sees the mirror image. No two-way exchange can tell.
  EXPECT_NEAR(sim.Error(0, 1), -20.0 * kMs, 1.0 * kMs);
  EXPECT_NEAR(sim.Error(1, 0), +20.0 * kMs, 1.0 * kMs);
  EXPECT_LE(std::abs(sim.Error(0, 1)), sim.Estimate(0, 1).asymmetry_bound_ns);
  EXPECT_NEAR(sim.Estimate(0, 1).asymmetry_bound_ns, 30.0 * kMs, 2.0 * kMs);
  // Pairs on symmetric links are unaffected.
  EXPECT_LT(std::abs(sim.Error(0, 2)), 1.0 * kMs);
  EXPECT_LT(std::abs(sim.Error(2, 1)), 1.0 * kMs);
  std::printf(
      "[ figures  ] asymmetric 10/50 ms: error 0->1 %.3f ms, 1->0 %.3f ms (bound %.1f ms)\n",
      sim.Error(0, 1) / kMs, sim.Error(1, 0) / kMs, sim.Estimate(0, 1).asymmetry_bound_ns / kMs);
}

TEST(ClockSyncSimulation, DuplicatesAndHeavyReorderingDoNotMatter) {
  LinkOptions link = LossyDelayedLink();
  link.duplicate_probability = 0.3;
  link.reorder_probability = 0.3;
  link.reorder_delay_max_s = 0.3;  // beyond the burst spacing: responses overtake
  NetworkOptions network;
  network.seed = 11;
  network.default_link = link;
  ClockSyncOptions every_second = Requests();  // the matched responses below assume 1 Hz
  every_second.settled_std_s = 0.0;
  SyncSimulation sim(network, SwarmClocks(), every_second);
  sim.RunUntil(120 * kS);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (i == j) continue;
      EXPECT_LT(std::abs(sim.Error(i, j)), 2.0 * kMs) << i << " -> " << j;
      const ClockSyncStats stats = sim.sync(i).Stats(j);
      EXPECT_EQ(stats.exchanges_invalid, 0u);
      EXPECT_GT(stats.responses_matched, 40u);
      // The teammate's current stamp maps to our current time.
      int64_t local = 0;
      ASSERT_TRUE(sim.sync(i).ToLocal(j, sim.clock(j).Local(sim.now_ns()), &local));
      EXPECT_LT(std::abs(local - sim.clock(i).Local(sim.now_ns())), 2 * kMs);
    }
  }
}

TEST(ClockSyncSimulation, DeterministicForASeed) {
  NetworkOptions network;
  network.seed = 5;
  network.default_link = LossyDelayedLink();
  SyncSimulation a(network, SwarmClocks(), Requests());
  SyncSimulation b(network, SwarmClocks(), Requests());
  a.RunUntil(30 * kS);
  b.RunUntil(30 * kS);
  EXPECT_EQ(a.Estimate(0, 1).offset_ns, b.Estimate(0, 1).offset_ns);
  EXPECT_EQ(a.Estimate(2, 0).std_ns, b.Estimate(2, 0).std_ns);
}

// ---------------------------------------------------------------------------
// State echo (the default): the timestamps travel in the 10 Hz state
// broadcasts, each state echoes at most 2 teammates' states (each teammate at
// most every 0.2 s), so a pair of a 3-drone swarm gets up to 5 exchanges per
// second each way, and no TimeSync packet is sent.

TEST(ClockSyncSimulation, StateEchoNominalLink) {
  const CaseFigures f = RunCase(LinkOptions(), ClockSyncOptions(), 5, 60, 2);
  Print("state echo, 5 ms +- 1 ms", f, 2);
  EXPECT_LT(f.max_abs_ms, 1.0);
  EXPECT_LT(f.rms_ms, 0.3);
  EXPECT_LE(f.within_2ms_from_s, 2.0);
  EXPECT_GE(f.within_3_sigma, 0.97);
}

TEST(ClockSyncSimulation, StateEchoThirtyPercentLossAndTwoHundredMilliseconds) {
  const CaseFigures f = RunCase(LossyDelayedLink(), ClockSyncOptions(), 10, 120, 10);
  Print("state echo, 30 % loss, 200 ms +- 1 ms, 20 % held back U(0, 50 ms)", f, 10);
  EXPECT_LT(f.rms_ms, 0.5);
  EXPECT_LT(f.max_abs_ms, 2.0);
  EXPECT_LT(f.within_2ms_from_s, 10.0);
  EXPECT_GE(f.within_3_sigma, 0.97);
}

TEST(ClockSyncSimulation, StateEchoSymmetricJitter) {
  // As SymmetricJitterNeedsManyExchanges: the bound is 2 x 14 ms / sqrt(N);
  // the echoes give about 5 x 0.49 exchanges per second instead of 0.49, but
  // gain less than sqrt(5) on the 1 Hz requests (measured: rms 2.76 against
  // 3.26 ms): the robust fit's delay weighting, not the exchange count, limits.
  LinkOptions link;
  link.latency_mean_s = 0.2;
  link.jitter_std_s = 0.02;
  link.loss_probability = 0.3;
  const CaseFigures f = RunCase(link, ClockSyncOptions(), 5, 120, 60);
  Print("state echo, 30 % loss, 200 ms +- 20 ms, 60-120 s", f, 60);
  const CaseFigures requests = RunCase(link, Requests(), 5, 120, 60);
  Print("requests at 1 Hz, the same", requests, 60);
  EXPECT_GE(f.within_3_sigma, 0.97);
  EXPECT_LT(f.rms_ms, requests.rms_ms);
  EXPECT_LT(f.rms_ms, 3.5);
}

/// The live faults-A proxy (tools/run_live_swarm.sh): 30 % loss, 200 ms with
/// a normal jitter of 10 ms on each leg, 10 % of the packets held back
/// U(0, 50 ms): symmetric jitter and a one-sided tail at once.
LinkOptions LiveFaultsLink() {
  LinkOptions link;
  link.latency_mean_s = 0.2;
  link.jitter_std_s = 0.01;
  link.loss_probability = 0.3;
  link.reorder_probability = 0.1;
  link.reorder_delay_max_s = 0.05;
  return link;
}

TEST(ClockSyncSimulation, StateEchoLiveFaultsLinkReachesTheAveragingBound) {
  // One exchange is off by N(0, 10 / sqrt(2) ms) plus the held-back tail;
  // about 4.9 exchanges per second survive the loss both ways, so after 60 s
  // (offset and drift fitted) no estimator does better than about
  // 2 x 7.1 ms / sqrt(290) = 0.83 ms at the end of the window.
  ClockSyncOptions one_end;
  one_end.report_period_s = 0.0;
  const CaseFigures alone = RunCase(LiveFaultsLink(), one_end, 10, 60, 60);
  Print("state echo, live faults A link (200 ms +- 10 ms, 10 % held U(0, 50 ms)), at 60 s, "
        "one end", alone, 60);
  EXPECT_LT(alone.rms_ms, 1.6);
  EXPECT_GE(alone.within_3_sigma, 0.95);
  // Both ends: each fuses the other's report of its estimate.
  const CaseFigures f = RunCase(LiveFaultsLink(), ClockSyncOptions(), 10, 60, 60);
  Print("the same, both ends", f, 60);
  EXPECT_LT(f.rms_ms, 0.9 * alone.rms_ms);
  EXPECT_GE(f.within_3_sigma, 0.95);
}

/// netem's "delay 200ms 1ms reorder 25%" (and loss 30 %): a quarter of the
/// packets skip the path delay. An exchange with one fast leg is off by
/// 100 ms and has the shortest round trip but one (both legs fast).
LinkOptions FastLaneLink() {
  LinkOptions link;
  link.latency_mean_s = 0.2;
  link.jitter_std_s = 0.001;
  link.loss_probability = 0.3;
  link.skip_delay_probability = 0.25;
  return link;
}

TEST(ClockSyncSimulation, StateEchoPacketsThatSkipTheDelayAreLeftOut) {
  const CaseFigures f = RunCase(FastLaneLink(), ClockSyncOptions(), 10, 60, 10);
  Print("state echo, netem reorder 25 %: 30 % loss, 200 ms +- 1 ms, 25 % skip the delay", f, 10);
  EXPECT_LT(f.max_abs_ms, 2.0);
  EXPECT_LT(f.rms_ms, 0.75);
  EXPECT_GE(f.within_3_sigma, 0.97);
}

TEST(ClockSyncSimulation, AReportIsFusedWhenItAgreesAndRejectedWhenItDoesNot) {
  NetworkOptions network;
  network.seed = 4;
  SyncSimulation sim(network, SwarmClocks(), ClockSyncOptions());
  sim.RunUntil(20 * kS);
  const int64_t now_local = sim.clock(0).Local(sim.now_ns());
  ClockOffsetEstimate own = sim.sync(0).Estimate(1, now_local);
  ASSERT_TRUE(own.converged);
  // Drone 1 "reports" its estimate of drone 0's offset, 0.3 ms from ours
  // (-offset), with a std of 0.1 ms; then one 10 ms off.
  const ClockSyncStats before = sim.sync(0).Stats(1);
  const auto report_state = [&](int64_t reported_offset_of_0_ns) {
    EgoStateMessage state = net_test::MakeEgoState(1, 0, 1);
    state.stamp_ns = sim.clock(1).Local(sim.now_ns());
    state.send_delay_ns = 0;
    const int64_t us = reported_offset_of_0_ns / 1000;
    state.offset_report = ClockOffsetReport{0, static_cast<uint16_t>(static_cast<uint64_t>(us)), 2};
    sim.mutable_sync(0).NoteTeammateState(state, now_local);
  };
  own = sim.sync(0).Estimate(1, now_local);
  report_state(-(own.offset_ns + 300'000));
  ClockOffsetEstimate fused = sim.sync(0).Estimate(1, now_local);
  EXPECT_EQ(sim.sync(0).Stats(1).reports_used, before.reports_used + 1);
  EXPECT_GT(fused.report_weight, 0.0);
  // The fused offset lies between ours and the report, by its weight.
  // (within 5 %: the report is quantized to 1 us and carried from its stamp
  // to now with our drift).
  EXPECT_NEAR(static_cast<double>(fused.offset_ns - own.offset_ns), fused.report_weight * 300'000,
              15'000);
  EXPECT_LT(fused.std_ns, own.std_ns);
  report_state(-(own.offset_ns + 10'000'000));
  EXPECT_EQ(sim.sync(0).Stats(1).reports_rejected, before.reports_rejected + 1);
  EXPECT_EQ(sim.sync(0).Estimate(1, now_local).offset_ns, fused.offset_ns);  // the earlier one stays
}

TEST(ClockSyncSimulation, StateEchoAsymmetricPathIsBiasedByHalfTheAsymmetry) {
  const NetworkOptions network = AsymmetricNetwork();
  SyncSimulation sim(network, SwarmClocks(), ClockSyncOptions());
  sim.RunUntil(30 * kS);
  EXPECT_NEAR(sim.Error(0, 1), -20.0 * kMs, 1.0 * kMs);
  EXPECT_NEAR(sim.Error(1, 0), +20.0 * kMs, 1.0 * kMs);
  EXPECT_LT(std::abs(sim.Error(0, 2)), 1.0 * kMs);
  EXPECT_LT(std::abs(sim.Error(2, 1)), 1.0 * kMs);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (i == j) continue;
      const ClockSyncStats stats = sim.sync(i).Stats(j);
      EXPECT_EQ(stats.requests_sent, 0u);
      EXPECT_EQ(stats.exchanges_invalid, 0u);
      EXPECT_EQ(stats.echoes_unmatched, 0u);
      // 30 s at up to 5 echoes per second, none lost: about 150.
      EXPECT_GT(stats.echoes_matched, 120u) << i << " -> " << j;
    }
  }
}

TEST(ClockSyncSimulation, StateEchoDuplicatesAndHeavyReorderingDoNotMatter) {
  LinkOptions link = LossyDelayedLink();
  link.duplicate_probability = 0.3;
  link.reorder_probability = 0.3;
  link.reorder_delay_max_s = 0.3;
  NetworkOptions network;
  network.seed = 11;
  network.default_link = link;
  SyncSimulation sim(network, SwarmClocks(), ClockSyncOptions());
  sim.RunUntil(60 * kS);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (i == j) continue;
      EXPECT_LT(std::abs(sim.Error(i, j)), 2.0 * kMs) << i << " -> " << j;
      EXPECT_EQ(sim.sync(i).Stats(j).exchanges_invalid, 0u);
    }
  }
}

}  // namespace
}  // namespace swarmlio::net
