// SimulatedNetwork: determinism, configured statistics, latency bounds,
// reordering, bandwidth, addressing.
#include "swarmlio/net/simulated_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

namespace swarmlio::net {
namespace {

constexpr int64_t kMs = 1'000'000;

std::unique_ptr<SimulatedNetwork> MakeNetwork(const NetworkOptions& options,
                                              const std::vector<int>& ids) {
  std::unique_ptr<SimulatedNetwork> network;
  const Status s = SimulatedNetwork::Create(options, ids, &network);
  EXPECT_TRUE(s.ok()) << s.message();
  return network;
}

/// A packet whose first 4 bytes number it.
std::vector<uint8_t> Numbered(uint32_t n, size_t size = 100) {
  std::vector<uint8_t> bytes(size, 0xAB);
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<uint8_t>(n >> (8 * i));
  return bytes;
}
uint32_t NumberOf(const Datagram& d) {
  uint32_t n = 0;
  for (int i = 0; i < 4; ++i) n |= static_cast<uint32_t>(d.bytes[i]) << (8 * i);
  return n;
}

/// Sends `count` numbered packets from -> to every `period_ns`, polling the
/// receiver after each send; returns everything received (final poll far later).
std::vector<Datagram> Stream(
    SimulatedNetwork* network, int from, int to, int count, int64_t period_ns, size_t size = 100) {
  std::vector<Datagram> received;
  for (int i = 0; i < count; ++i) {
    const int64_t now = i * period_ns;
    const std::vector<uint8_t> bytes = Numbered(static_cast<uint32_t>(i), size);
    EXPECT_TRUE(network->Endpoint(from)->Send(now, to, bytes.data(), bytes.size()).ok());
    EXPECT_TRUE(network->Endpoint(to)->Poll(now, &received).ok());
  }
  EXPECT_TRUE(network->Endpoint(to)->Poll(std::numeric_limits<int64_t>::max(), &received).ok());
  return received;
}

NetworkOptions Ideal(double latency_s) {
  NetworkOptions o;
  o.default_link.latency_mean_s = latency_s;
  o.default_link.jitter_std_s = 0.0;
  return o;
}

TEST(SimulatedNetwork, IdealLinkDeliversEverythingInOrderWithExactLatency) {
  auto network = MakeNetwork(Ideal(0.004), {0, 1});
  const auto received = Stream(network.get(), 0, 1, 1000, kMs);
  ASSERT_EQ(received.size(), 1000u);
  for (size_t i = 0; i < received.size(); ++i) {
    EXPECT_EQ(NumberOf(received[i]), i);
    EXPECT_EQ(received[i].source_id, 0);
    EXPECT_EQ(received[i].arrival_ns, static_cast<int64_t>(i) * kMs + 4 * kMs);
  }
  const LinkStats stats = network->Stats(0, 1);
  EXPECT_EQ(stats.sent, 1000u);
  EXPECT_EQ(stats.delivered, 1000u);
  EXPECT_EQ(stats.dropped_loss + stats.dropped_queue + stats.duplicated + stats.reordered, 0u);
  EXPECT_EQ(stats.bytes_sent, 100000u);
  EXPECT_EQ(stats.bytes_delivered, 100000u);
  EXPECT_NEAR(stats.latency_max_s, 0.004, 1e-12);
  EXPECT_EQ(stats.InFlight(), 0u);
  EXPECT_EQ(network->Stats(1, 0).sent, 0u);
}

TEST(SimulatedNetwork, PollReturnsOnlyArrivedPackets) {
  auto network = MakeNetwork(Ideal(0.010), {3, 7});
  const auto bytes = Numbered(1);
  ASSERT_TRUE(network->Endpoint(3)->Send(100 * kMs, 7, bytes.data(), bytes.size()).ok());
  EXPECT_EQ(network->NextArrivalNs(), 110 * kMs);
  std::vector<Datagram> received;
  ASSERT_TRUE(network->Endpoint(7)->Poll(110 * kMs - 1, &received).ok());
  EXPECT_TRUE(received.empty());
  ASSERT_TRUE(network->Endpoint(7)->Poll(110 * kMs, &received).ok());
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].bytes, bytes);
  EXPECT_EQ(network->NextArrivalNs(), std::numeric_limits<int64_t>::max());
  ASSERT_TRUE(network->Endpoint(7)->Poll(200 * kMs, &received).ok());
  EXPECT_EQ(received.size(), 1u);  // nothing twice
}

NetworkOptions Lossy(int64_t seed) {
  NetworkOptions o;
  o.seed = seed;
  o.default_link.latency_mean_s = 0.005;
  o.default_link.jitter_std_s = 0.003;
  o.default_link.loss_probability = 0.2;
  o.default_link.duplicate_probability = 0.1;
  o.default_link.reorder_probability = 0.05;
  o.default_link.bandwidth_bytes_per_s = 200000.0;
  return o;
}

/// Every drone broadcasts each ms; everyone polls. Returns all datagrams per receiver.
std::vector<std::vector<Datagram>> RunSwarm(SimulatedNetwork* network, int steps) {
  const std::vector<int> ids = network->drone_ids();
  std::vector<std::vector<Datagram>> inbox(ids.size());
  for (int step = 0; step < steps; ++step) {
    const int64_t now = step * kMs;
    for (int id : ids) {
      const auto bytes = Numbered(static_cast<uint32_t>(step * 100 + id), 50 + step % 400);
      EXPECT_TRUE(network->Endpoint(id)->Send(now, kBroadcastId, bytes.data(), bytes.size()).ok());
    }
    for (size_t r = 0; r < ids.size(); ++r) {
      EXPECT_TRUE(network->Endpoint(ids[r])->Poll(now, &inbox[r]).ok());
    }
  }
  return inbox;
}

void ExpectSameDeliveries(const std::vector<std::vector<Datagram>>& a,
                          const std::vector<std::vector<Datagram>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t r = 0; r < a.size(); ++r) {
    ASSERT_EQ(a[r].size(), b[r].size());
    for (size_t i = 0; i < a[r].size(); ++i) {
      EXPECT_EQ(a[r][i].source_id, b[r][i].source_id);
      EXPECT_EQ(a[r][i].arrival_ns, b[r][i].arrival_ns);
      EXPECT_EQ(a[r][i].bytes, b[r][i].bytes);
    }
  }
}

TEST(SimulatedNetwork, SameSeedSameDeliveriesBitForBit) {
  auto first = MakeNetwork(Lossy(5), {4, 0, 9});
  auto second = MakeNetwork(Lossy(5), {9, 4, 0});  // id order given does not matter
  const auto a = RunSwarm(first.get(), 2000);
  const auto b = RunSwarm(second.get(), 2000);
  ExpectSameDeliveries(a, b);
  for (int from : {0, 4, 9}) {
    for (int to : {0, 4, 9}) {
      const LinkStats sa = first->Stats(from, to);
      const LinkStats sb = second->Stats(from, to);
      EXPECT_EQ(sa.delivered, sb.delivered);
      EXPECT_EQ(sa.dropped_loss, sb.dropped_loss);
      EXPECT_EQ(sa.reordered, sb.reordered);
      EXPECT_EQ(sa.latency_sum_s, sb.latency_sum_s);
    }
  }
  auto other_seed = MakeNetwork(Lossy(6), {0, 4, 9});
  const auto c = RunSwarm(other_seed.get(), 2000);
  bool differs = false;
  for (size_t r = 0; r < a.size() && !differs; ++r) {
    differs = a[r].size() != c[r].size();
    for (size_t i = 0; i < a[r].size() && !differs; ++i) {
      differs = a[r][i].arrival_ns != c[r][i].arrival_ns;
    }
  }
  EXPECT_TRUE(differs);
}

TEST(SimulatedNetwork, LinksHaveIndependentRandomStreams) {
  NetworkOptions o = Lossy(11);
  o.default_link.bandwidth_bytes_per_s = 0.0;
  auto alone = MakeNetwork(o, {0, 1, 2});
  auto busy = MakeNetwork(o, {0, 1, 2});
  const auto bytes = Numbered(0);
  // Extra traffic on 2 -> 1 in `busy` only.
  for (int i = 0; i < 500; ++i) {
    ASSERT_TRUE(busy->Endpoint(2)->Send(i * kMs, 1, bytes.data(), bytes.size()).ok());
  }
  const auto a = Stream(alone.get(), 0, 1, 500, kMs);
  auto b_all = Stream(busy.get(), 0, 1, 500, kMs);
  std::vector<Datagram> b;
  for (auto& d : b_all) {
    if (d.source_id == 0) b.push_back(d);
  }
  ExpectSameDeliveries({a}, {b});
}

TEST(SimulatedNetwork, LossAndDuplicationMatchTheirProbabilities) {
  NetworkOptions o;
  o.seed = 3;
  o.default_link.loss_probability = 0.15;
  o.default_link.duplicate_probability = 0.05;
  auto network = MakeNetwork(o, {0, 1});
  constexpr int kPackets = 40000;
  Stream(network.get(), 0, 1, kPackets, kMs);
  const LinkStats s = network->Stats(0, 1);
  const double n = kPackets;
  // 4.5 sigma bands of the binomial counts.
  const double loss = s.dropped_loss / n;
  EXPECT_NEAR(loss, 0.15, 4.5 * std::sqrt(0.15 * 0.85 / n));
  const double survivors = n - s.dropped_loss;
  const double dup = s.duplicated / survivors;
  EXPECT_NEAR(dup, 0.05, 4.5 * std::sqrt(0.05 * 0.95 / survivors));
  EXPECT_EQ(s.delivered, s.sent - s.dropped_loss + s.duplicated);
  EXPECT_EQ(s.InFlight(), 0u);
}

TEST(SimulatedNetwork, LatencyStaysWithinBoundsAndMatchesMeanAndStd) {
  NetworkOptions o;
  o.default_link.latency_mean_s = 0.020;
  o.default_link.jitter_std_s = 0.004;
  auto network = MakeNetwork(o, {0, 1});
  constexpr int kPackets = 20000;
  const auto received = Stream(network.get(), 0, 1, kPackets, 10 * kMs);
  ASSERT_EQ(received.size(), static_cast<size_t>(kPackets));
  double sum = 0.0, sum2 = 0.0;
  for (const Datagram& d : received) {
    const double latency = (d.arrival_ns - static_cast<int64_t>(NumberOf(d)) * 10 * kMs) * 1e-9;
    EXPECT_GE(latency, 0.0);
    EXPECT_LE(latency, 0.020 + 6 * 0.004 + 1e-9);  // Irwin-Hall support is +-6 sigma
    sum += latency;
    sum2 += latency * latency;
  }
  const double mean = sum / kPackets;
  const double std = std::sqrt(sum2 / kPackets - mean * mean);
  EXPECT_NEAR(mean, 0.020, 4.5 * 0.004 / std::sqrt(kPackets));
  EXPECT_NEAR(std, 0.004, 0.0002);
}

TEST(SimulatedNetwork, JitterTruncatesAtZeroDelay) {
  NetworkOptions o;
  o.default_link.latency_mean_s = 0.001;
  o.default_link.jitter_std_s = 0.005;
  auto network = MakeNetwork(o, {0, 1});
  const auto received = Stream(network.get(), 0, 1, 5000, 20 * kMs);
  ASSERT_EQ(received.size(), 5000u);
  for (const Datagram& d : received) {
    EXPECT_GE(d.arrival_ns, static_cast<int64_t>(NumberOf(d)) * 20 * kMs);
  }
}

bool InOrder(const std::vector<Datagram>& received) {
  for (size_t i = 1; i < received.size(); ++i) {
    if (NumberOf(received[i]) < NumberOf(received[i - 1])) return false;
  }
  return true;
}

TEST(SimulatedNetwork, ReorderingHappensWithJitterAndNeverWithout) {
  NetworkOptions o;
  o.default_link.latency_mean_s = 0.010;
  o.default_link.jitter_std_s = 0.0;
  auto steady = MakeNetwork(o, {0, 1});
  EXPECT_TRUE(InOrder(Stream(steady.get(), 0, 1, 5000, kMs)));
  EXPECT_EQ(steady->Stats(0, 1).reordered, 0u);

  o.default_link.jitter_std_s = 0.003;  // 3 ms spread, 1 ms spacing
  auto jittery = MakeNetwork(o, {0, 1});
  EXPECT_FALSE(InOrder(Stream(jittery.get(), 0, 1, 5000, kMs)));
  EXPECT_GT(jittery->Stats(0, 1).reordered, 100u);

  o.default_link.jitter_std_s = 0.0;
  o.default_link.reorder_probability = 0.1;
  o.default_link.reorder_delay_max_s = 0.02;
  auto explicit_reorder = MakeNetwork(o, {0, 1});
  EXPECT_FALSE(InOrder(Stream(explicit_reorder.get(), 0, 1, 5000, kMs)));
  EXPECT_GT(explicit_reorder->Stats(0, 1).reordered, 100u);
}

TEST(SimulatedNetwork, BandwidthCapQueuesAndDrops) {
  NetworkOptions o = Ideal(0.0);
  o.default_link.bandwidth_bytes_per_s = 10000.0;  // 100-byte packet: 10 ms on the air
  o.default_link.max_queue_delay_s = 0.1;
  auto network = MakeNetwork(o, {0, 1});
  const auto received = Stream(network.get(), 0, 1, 1000, kMs);  // offered 10x capacity
  const LinkStats s = network->Stats(0, 1);
  EXPECT_GT(s.dropped_queue, 800u);
  EXPECT_EQ(s.delivered + s.dropped_queue, 1000u);
  for (size_t i = 1; i < received.size(); ++i) {
    EXPECT_GE(received[i].arrival_ns - received[i - 1].arrival_ns, 10 * kMs);
  }
  EXPECT_LE(s.latency_max_s, 0.1 + 0.01 + 1e-9);
}

TEST(SimulatedNetwork, BroadcastAddressingAndErrors) {
  auto network = MakeNetwork(Ideal(0.001), {0, 1, 2});
  const auto bytes = Numbered(5);
  Transport* sender = network->Endpoint(1);
  ASSERT_NE(sender, nullptr);
  EXPECT_EQ(sender->self_id(), 1);
  ASSERT_TRUE(sender->Send(0, kBroadcastId, bytes.data(), bytes.size()).ok());
  std::vector<Datagram> r0, r1, r2;
  ASSERT_TRUE(network->Endpoint(0)->Poll(kMs, &r0).ok());
  ASSERT_TRUE(network->Endpoint(1)->Poll(kMs, &r1).ok());
  ASSERT_TRUE(network->Endpoint(2)->Poll(kMs, &r2).ok());
  EXPECT_EQ(r0.size(), 1u);
  EXPECT_EQ(r1.size(), 0u);
  EXPECT_EQ(r2.size(), 1u);

  EXPECT_EQ(sender->Send(0, 1, bytes.data(), bytes.size()).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(sender->Send(0, 5, bytes.data(), bytes.size()).code(), Status::Code::kNotFound);
  EXPECT_EQ(sender->Send(0, 99, bytes.data(), bytes.size()).code(), Status::Code::kNotFound);
  const std::vector<uint8_t> oversized(kMaxPacketBytes + 1, 0);
  EXPECT_EQ(sender->Send(0, 0, oversized.data(), oversized.size()).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(sender->Send(0, 0, bytes.data(), 0).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(network->Endpoint(5), nullptr);
  EXPECT_EQ(network->Endpoint(-1), nullptr);
}

TEST(SimulatedNetwork, LinkOverridesApplyPerDirection) {
  NetworkOptions o = Ideal(0.001);
  LinkOverride cut;
  cut.from_id = 0;
  cut.to_id = 2;
  cut.link.loss_probability = 1.0;
  o.links.push_back(cut);
  LinkOverride slow_into_1;
  slow_into_1.to_id = 1;
  slow_into_1.link.latency_mean_s = 0.050;
  slow_into_1.link.jitter_std_s = 0.0;
  o.links.push_back(slow_into_1);
  auto network = MakeNetwork(o, {0, 1, 2});
  EXPECT_EQ(Stream(network.get(), 0, 2, 100, kMs).size(), 0u);
  EXPECT_EQ(Stream(network.get(), 2, 0, 100, kMs).size(), 100u);
  const auto into_1 = Stream(network.get(), 0, 1, 10, kMs);
  ASSERT_EQ(into_1.size(), 10u);
  EXPECT_EQ(into_1[0].arrival_ns, 50 * kMs);
  EXPECT_EQ(network->TotalStats().dropped_loss, 100u);
}

TEST(SimulatedNetwork, CreateRejectsBadInput) {
  std::unique_ptr<SimulatedNetwork> network;
  EXPECT_FALSE(SimulatedNetwork::Create(NetworkOptions(), {0, 1, 0}, &network).ok());
  EXPECT_FALSE(SimulatedNetwork::Create(NetworkOptions(), {0, kMaxSwarmSize}, &network).ok());
  NetworkOptions bad;
  bad.default_link.loss_probability = 1.5;
  const Status s = SimulatedNetwork::Create(bad, {0, 1}, &network);
  EXPECT_NE(s.message().find("network.default_link.loss_probability"), std::string::npos)
      << s.message();
  NetworkOptions absent;
  LinkOverride o;
  o.from_id = 7;
  absent.links.push_back(o);
  EXPECT_NE(SimulatedNetwork::Create(absent, {0, 1}, &network).message().find("links[0]"),
            std::string::npos);
  EXPECT_EQ(network, nullptr);
}

}  // namespace
}  // namespace swarmlio::net
