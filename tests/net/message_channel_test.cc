// MessageChannel over the simulated network: typed messages arrive intact,
// once, in arrival order; foreign and corrupt packets are counted, not returned.
#include "swarmlio/net/message_channel.h"

#include <gtest/gtest.h>

#include <limits>
#include <set>
#include <utility>
#include <variant>
#include <vector>

#include "swarmlio/net/simulated_network.h"
#include "tests/net/net_test_util.h"

namespace swarmlio::net {
namespace {

using net_test::ExpectSameMessage;
using net_test::MakeCodec;
using net_test::MakeEgoState;
using net_test::MakeTimeSync;

constexpr int64_t kMs = 1'000'000;

TEST(MessageChannel, DeliversEachMessageOnceDespiteDuplication) {
  NetworkOptions o;
  o.seed = 8;
  o.default_link.loss_probability = 0.1;
  o.default_link.duplicate_probability = 0.3;
  o.default_link.jitter_std_s = 0.01;
  std::unique_ptr<SimulatedNetwork> network;
  ASSERT_TRUE(SimulatedNetwork::Create(o, {0, 1, 2}, &network).ok());
  const PacketCodec codec = MakeCodec();
  std::vector<MessageChannel> channels;
  for (int id : {0, 1, 2}) channels.emplace_back(&codec, network->Endpoint(id));

  std::vector<std::vector<ReceivedMessage>> inbox(3);
  std::vector<EgoStateMessage> sent;
  for (int step = 0; step < 300; ++step) {
    const int64_t now = step * 33 * kMs;  // 30 Hz scans
    for (int id = 0; id < 3; ++id) {
      EgoStateMessage m = MakeEgoState(id, step % 3, static_cast<uint64_t>(step * 3 + id));
      ASSERT_TRUE(channels[id].Send(now, kBroadcastId, m).ok());
      sent.push_back(m);
    }
    for (int id = 0; id < 3; ++id) ASSERT_TRUE(channels[id].Poll(now, &inbox[id]).ok());
  }
  for (int id = 0; id < 3; ++id) {
    ASSERT_TRUE(channels[id].Poll(std::numeric_limits<int64_t>::max(), &inbox[id]).ok());
    std::set<std::pair<int, uint32_t>> seen;
    int64_t last_arrival = 0;
    for (const ReceivedMessage& r : inbox[id]) {
      EXPECT_NE(r.header.sender_id, id);
      EXPECT_TRUE(seen.insert({r.header.sender_id, r.header.sequence}).second);
      EXPECT_GE(r.arrival_ns, last_arrival);
      last_arrival = r.arrival_ns;
      ExpectSameMessage(sent[r.header.sequence * 3 + r.header.sender_id], r.message);
    }
    const ChannelStats& s = channels[id].stats();
    EXPECT_EQ(s.sent, 300u);
    EXPECT_EQ(s.rejected, 0u);
    EXPECT_GT(s.duplicates, 0u);
    EXPECT_EQ(s.received, inbox[id].size());
  }
  // Channel-level duplicates equal the network's duplicated copies that arrived.
  const LinkStats total = network->TotalStats();
  uint64_t duplicates = 0;
  for (const MessageChannel& c : channels) duplicates += c.stats().duplicates;
  EXPECT_EQ(duplicates, total.duplicated);
}

TEST(MessageChannel, RejectsForeignKeysAndWrongSender) {
  std::unique_ptr<SimulatedNetwork> network;
  ASSERT_TRUE(SimulatedNetwork::Create(NetworkOptions(), {0, 1, 2}, &network).ok());
  const PacketCodec swarm = MakeCodec(1);
  const PacketCodec intruder = MakeCodec(2);
  MessageChannel receiver(&swarm, network->Endpoint(0));
  MessageChannel friendly(&swarm, network->Endpoint(1));
  MessageChannel hostile(&intruder, network->Endpoint(2));

  ASSERT_TRUE(friendly.Send(0, 0, MakeTimeSync(1, 0, false)).ok());
  ASSERT_TRUE(hostile.Send(0, 0, MakeTimeSync(2, 0, false)).ok());
  EXPECT_EQ(friendly.Send(0, 0, MakeTimeSync(2, 0, false)).code(),
            Status::Code::kInvalidArgument);  // not its own id
  EXPECT_EQ(friendly.Send(0, 0, MakeEgoState(1, EgoStateMessage::kMaxObservations + 1, 1)).code(),
            Status::Code::kInvalidArgument);

  std::vector<ReceivedMessage> inbox;
  ASSERT_TRUE(receiver.Poll(kMs * 100, &inbox).ok());
  ASSERT_EQ(inbox.size(), 1u);
  EXPECT_EQ(inbox[0].header.sender_id, 1);
  EXPECT_EQ(receiver.stats().rejected, 1u);
  EXPECT_NE(receiver.stats().last_reject_reason.find("authentication"), std::string::npos);
}

/// A transport that hears its own sends, as a UDP broadcast socket does.
class EchoTransport : public Transport {
 public:
  int self_id() const override { return 4; }
  Status Send(int64_t now_ns, int, const uint8_t* data, size_t size) override {
    Datagram d;
    d.arrival_ns = now_ns;
    d.bytes.assign(data, data + size);
    queue_.push_back(std::move(d));
    return Status::Ok();
  }
  Status Poll(int64_t, std::vector<Datagram>* received) override {
    for (auto& d : queue_) received->push_back(std::move(d));
    queue_.clear();
    return Status::Ok();
  }

 private:
  std::vector<Datagram> queue_;
};

TEST(MessageChannel, DropsItsOwnEchoedPackets) {
  const PacketCodec codec = MakeCodec();
  EchoTransport echo;
  MessageChannel channel(&codec, &echo);
  ASSERT_TRUE(channel.Send(0, kBroadcastId, MakeTimeSync(4, 1, false)).ok());
  std::vector<ReceivedMessage> inbox;
  ASSERT_TRUE(channel.Poll(0, &inbox).ok());
  EXPECT_TRUE(inbox.empty());
  EXPECT_EQ(channel.stats().own_packets, 1u);
}

// A state sent too late for its send delay to be encoded (a loaded machine)
// still leaves; its echoes and offset report, which need the delay, do not.
// The report used to stay and the encoder refused the whole message.
TEST(MessageChannel, AStateSentTooLateForItsDelayStillLeavesWithoutItsClockItems) {
  const PacketCodec codec = MakeCodec();
  EchoTransport echo;
  MessageChannel channel(&codec, &echo);
  EgoStateMessage m = MakeEgoState(/*sender=*/4, 1, 154, 0, /*num_echoes=*/1);
  m.offset_report = ClockOffsetReport{63, 0xFFFE, 1};
  const int64_t now_ns = m.stamp_ns + int64_t{3600} * 1000 * kMs;  // an hour late
  ASSERT_TRUE(channel.Send(now_ns, kBroadcastId, m).ok());
  EXPECT_EQ(channel.stats().sent, 1u);
  EXPECT_EQ(channel.stats().send_delay_unknown, 1u);
  EXPECT_EQ(channel.stats().echoes_dropped, 1u);
  // The state itself is intact.
  std::vector<Datagram> sent;
  ASSERT_TRUE(echo.Poll(now_ns, &sent).ok());
  ASSERT_EQ(sent.size(), 1u);
  DecodedPacket decoded;
  ASSERT_TRUE(codec.Decode(sent[0].bytes.data(), sent[0].bytes.size(), &decoded).ok());
  const auto* state = std::get_if<EgoStateMessage>(&decoded.message);
  ASSERT_NE(state, nullptr);
  EXPECT_FALSE(state->offset_report.has_value());
  EXPECT_TRUE(state->echoes.empty());
  EXPECT_EQ(state->stamp_ns, m.stamp_ns);
  EXPECT_EQ(state->p_bj_in_Gj, m.p_bj_in_Gj);
}

}  // namespace
}  // namespace swarmlio::net
