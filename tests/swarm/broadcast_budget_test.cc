// swarm::BroadcastBudget (the token bucket on the sensor clock) and
// swarm::SendRotation (least recently sent first), include/swarmlio/swarm/
// broadcast_budget.h. The estimator's use of them, end to end, is in
// drone_estimator_test.cc (BroadcastBudgetTest).
#include "swarmlio/swarm/broadcast_budget.h"

#include <gtest/gtest.h>

#include <random>

namespace swarmlio::swarm {
namespace {

constexpr int64_t kMs = 1000000;

TEST(BroadcastBudget, StartsFullAndEarnsTheRateCappedAtTheBurst) {
  BroadcastBudgetOptions o;
  o.max_bytes_per_s = 1000.0;
  o.burst_s = 0.5;
  BroadcastBudget b(o);
  b.Refill(100 * kMs);
  EXPECT_DOUBLE_EQ(b.credit_bytes(), 500.0);  // a full bucket
  EXPECT_TRUE(b.TrySpend(400));
  EXPECT_FALSE(b.TrySpend(101));  // 100 left: nothing spent
  EXPECT_DOUBLE_EQ(b.credit_bytes(), 100.0);
  b.Refill(300 * kMs);  // 0.2 s x 1000 B/s
  EXPECT_DOUBLE_EQ(b.credit_bytes(), 300.0);
  b.Refill(250 * kMs);  // backwards: nothing earned
  EXPECT_DOUBLE_EQ(b.credit_bytes(), 300.0);
  b.Refill(10300 * kMs);  // 10 s later: capped
  EXPECT_DOUBLE_EQ(b.credit_bytes(), 500.0);
}

TEST(BroadcastBudget, MandatoryBytesGoNegativeAndBlockOptionalOnesUntilRepaid) {
  BroadcastBudgetOptions o;
  o.max_bytes_per_s = 1000.0;
  o.burst_s = 0.1;
  BroadcastBudget b(o);
  b.Refill(0);
  b.Spend(300);
  EXPECT_DOUBLE_EQ(b.credit_bytes(), -200.0);
  EXPECT_FALSE(b.TrySpend(1));
  EXPECT_EQ(b.Affordable(0, 10, 5), 0);
  b.Refill(250 * kMs);
  EXPECT_DOUBLE_EQ(b.credit_bytes(), 50.0);
  EXPECT_EQ(b.Affordable(0, 10, 99), 5);
  EXPECT_EQ(b.Affordable(20, 10, 99), 3);  // the first item also pays 20
  EXPECT_EQ(b.Affordable(0, 10, 2), 2);
  EXPECT_EQ(b.Affordable(45, 10, 99), 0);
}

TEST(BroadcastBudget, UnlimitedAffordsEverything) {
  BroadcastBudgetOptions o;
  o.max_bytes_per_s = 0.0;
  BroadcastBudget b(o);
  b.Refill(0);
  b.Spend(1 << 20);
  EXPECT_TRUE(b.TrySpend(1 << 20));
  EXPECT_EQ(b.Affordable(1 << 20, 1 << 20, 7), 7);
  EXPECT_EQ(b.WireBytes(100), 128u);
}

// The bound the budget promises: whatever is offered, over any window of W
// seconds at most rate x (W + burst) bytes go out (here no mandatory part
// beyond the rate). A budget that forgot to cap the credit, or refilled per
// call instead of per elapsed time, breaks it.
TEST(BroadcastBudget, AnyWindowStaysWithinRateTimesWindowPlusBurst) {
  BroadcastBudgetOptions o;
  o.max_bytes_per_s = 1450.0;
  o.burst_s = 0.5;
  BroadcastBudget b(o);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> item(5, 200);
  std::uniform_int_distribution<int> gap_ms(1, 150);
  std::vector<std::pair<int64_t, double>> sent;  // (stamp, bytes)
  int64_t t = 0;
  std::bernoulli_distribution idle(0.05);  // quiet stretches: the credit must not pile up
  for (int scan = 0; scan < 2000; ++scan) {
    t += (idle(rng) ? 3000 : gap_ms(rng)) * kMs;
    b.Refill(t);
    double bytes = 0;
    for (int k = 0; k < 10; ++k) {
      const int n = item(rng);
      if (b.TrySpend(n)) bytes += n;
    }
    sent.emplace_back(t, bytes);
  }
  for (double window_s : {0.1, 1.0, 10.0}) {
    size_t begin = 0;
    double in_window = 0;
    double worst = 0;
    for (size_t end = 0; end < sent.size(); ++end) {
      in_window += sent[end].second;
      while (sent[end].first - sent[begin].first > static_cast<int64_t>(window_s * 1e9)) {
        in_window -= sent[begin++].second;
      }
      worst = std::max(worst, in_window);
    }
    EXPECT_LE(worst, 1450.0 * (window_s + 0.5) + 1e-6) << window_s;
    if (window_s >= 10.0) {
      EXPECT_GT(worst, 0.9 * 1450.0 * window_s);  // and uses it
    }
  }
}

TEST(SendRotation, NeverSentFirstThenLeastRecentlySent) {
  SendRotation r;
  EXPECT_EQ(r.Order({5, 3, 9}), (std::vector<int>{3, 5, 9}));
  r.MarkSent(3);
  r.MarkSent(9);
  EXPECT_EQ(r.Order({9, 5, 3}), (std::vector<int>{5, 3, 9}));
  r.MarkSent(5);
  r.MarkSent(3);
  EXPECT_EQ(r.Order({3, 5, 9}), (std::vector<int>{9, 5, 3}));
  EXPECT_TRUE(r.EverSent(9));
  r.Forget(9);
  EXPECT_FALSE(r.EverSent(9));
  EXPECT_EQ(r.Order({3, 5, 9}), (std::vector<int>{9, 5, 3}));
}

}  // namespace
}  // namespace swarmlio::swarm
