// Decoding never trusts its input: truncations, extensions, random
// corruption, a wrong key, and well-authenticated but malformed payloads.
#include <gtest/gtest.h>
#include <sodium.h>

#include <cstring>
#include <limits>
#include <random>

#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/wire_format.h"
#include "tests/net/net_test_util.h"

namespace swarmlio::net {
namespace {

using net_test::AllExampleMessages;
using net_test::MakeCodec;
using net_test::MakeEgoState;
using net_test::MakeGlobalExtrinsic;
using net_test::MakeTimeSync;

constexpr uint64_t kKeySeed = 7;

/// Recomputes length and tag after a test edited the payload, so that the
/// payload checks (not the tag) must catch the edit.
void Resign(std::vector<uint8_t>* packet) {
  const size_t payload = packet->size() - kPacketOverheadBytes;
  (*packet)[10] = static_cast<uint8_t>(payload & 0xFF);
  (*packet)[11] = static_cast<uint8_t>(payload >> 8);
  const SwarmKey key = SwarmKey::ForSimulation(kKeySeed);
  crypto_auth(packet->data() + packet->size() - kTagBytes, packet->data(),
              packet->size() - kTagBytes, key.data());
}

std::vector<uint8_t> Encode(const SwarmMessage& m) {
  std::vector<uint8_t> packet;
  EXPECT_TRUE(MakeCodec(kKeySeed).Encode(m, 11, &packet).ok());
  return packet;
}

Status Decode(const std::vector<uint8_t>& packet) {
  DecodedPacket decoded;
  return MakeCodec(kKeySeed).Decode(packet.data(), packet.size(), &decoded);
}

void ExpectRejected(const std::vector<uint8_t>& packet, const std::string& reason) {
  const Status s = Decode(packet);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(reason), std::string::npos) << s.message();
}

TEST(PacketCodecRobustness, EveryTruncationAndExtensionIsRejected) {
  const PacketCodec codec = MakeCodec(kKeySeed);
  for (const SwarmMessage& message : AllExampleMessages()) {
    const std::vector<uint8_t> packet = Encode(message);
    DecodedPacket decoded;
    for (size_t length = 0; length < packet.size(); ++length) {
      // A copy of exactly `length` bytes, so ASan sees any over-read.
      const std::vector<uint8_t> prefix(packet.begin(), packet.begin() + length);
      EXPECT_FALSE(codec.Decode(prefix.data(), prefix.size(), &decoded).ok()) << length;
    }
    std::vector<uint8_t> longer = packet;
    longer.push_back(0);
    EXPECT_FALSE(codec.Decode(longer.data(), longer.size(), &decoded).ok());
  }
  DecodedPacket decoded;
  EXPECT_FALSE(codec.Decode(nullptr, 0, &decoded).ok());
}

TEST(PacketCodecRobustness, RandomCorruptionNeverCrashesAndIsRejected) {
  const PacketCodec codec = MakeCodec(kKeySeed);
  const std::vector<SwarmMessage> messages = AllExampleMessages();
  std::mt19937_64 rng(2024);
  int tag_rejections = 0;
  constexpr int kTrials = 20000;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<uint8_t> packet = Encode(messages[trial % messages.size()]);
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) {
      const size_t at = rng() % packet.size();
      packet[at] ^= static_cast<uint8_t>(1 + rng() % 255);  // never a no-op
    }
    DecodedPacket decoded;
    const Status s = codec.Decode(packet.data(), packet.size(), &decoded);
    ASSERT_FALSE(s.ok()) << "trial " << trial;
    if (s.message().find("authentication tag") != std::string::npos) ++tag_rejections;
  }
  // Most flips land in the payload or tag, where only the tag can notice.
  EXPECT_GT(tag_rejections, kTrials / 2);
}

TEST(PacketCodecRobustness, RandomGarbageIsRejected) {
  const PacketCodec codec = MakeCodec(kKeySeed);
  std::mt19937_64 rng(99);
  for (int trial = 0; trial < 5000; ++trial) {
    std::vector<uint8_t> bytes(rng() % (kMaxPacketBytes + 100));
    for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng());
    if (bytes.size() >= 2 && trial % 2 == 0) {  // half of them look like ours
      bytes[0] = kMagic0;
      bytes[1] = kMagic1;
    }
    DecodedPacket decoded;
    EXPECT_FALSE(codec.Decode(bytes.data(), bytes.size(), &decoded).ok());
  }
}

TEST(PacketCodecRobustness, WrongKeyIsRejected) {
  const std::vector<uint8_t> packet = Encode(MakeEgoState(1, 3, 1));
  const PacketCodec other = MakeCodec(kKeySeed + 1);
  DecodedPacket decoded;
  const Status s = other.Decode(packet.data(), packet.size(), &decoded);
  EXPECT_EQ(s.code(), Status::Code::kDataLoss);
  EXPECT_NE(s.message().find("authentication tag mismatch"), std::string::npos) << s.message();
}

TEST(PacketCodecRobustness, HeaderChecks) {
  const std::vector<uint8_t> good = Encode(MakeTimeSync(1, 2, true));
  std::vector<uint8_t> p = good;
  p[0] = 'X';
  ExpectRejected(p, "bad magic");
  p = good;
  p[2] = kProtocolVersion + 1;
  EXPECT_EQ(Decode(p).code(), Status::Code::kInvalidArgument);
  ExpectRejected(p, "unsupported protocol version " + std::to_string(kProtocolVersion + 1));
  p[2] = 1;  // version 1: GlobalExtrinsic without gravity
  ExpectRejected(p, "unsupported protocol version 1");
  p = good;
  p[3] = 9;
  ExpectRejected(p, "unknown message type 9");
  p = good;
  p[3] = 0;
  ExpectRejected(p, "unknown message type 0");
  p = good;
  p[5] = 1;
  ExpectRejected(p, "flags");
  p = good;
  p[4] = kMaxSwarmSize;
  ExpectRejected(p, "sender id 64");
  p = good;
  p[10] = static_cast<uint8_t>(p[10] + 1);
  ExpectRejected(p, "payload length");
  p = good;
  p[11] = 0xFF;
  ExpectRejected(p, "payload length");
  std::vector<uint8_t> huge(kMaxPacketBytes + 1, 0);
  ExpectRejected(huge, "exceeds the cap");
}

TEST(PacketCodecRobustness, AuthenticatedButMalformedPayloadsAreRejected) {
  constexpr size_t kCountOffset = kHeaderBytes + kEgoStateFixedBytes - 1;
  const std::vector<uint8_t> ego = Encode(MakeEgoState(1, 2, 5));
  {  // sanity: Resign alone keeps a packet valid
    std::vector<uint8_t> p = ego;
    Resign(&p);
    EXPECT_TRUE(Decode(p).ok());
  }
  {  // over-long list: a count above the cap, with the bytes present
    std::vector<uint8_t> p = Encode(MakeEgoState(1, EgoStateMessage::kMaxObservations, 5));
    p.insert(p.end() - kTagBytes, kObservationBytes, 0);
    p[kCountOffset] = EgoStateMessage::kMaxObservations + 1;
    Resign(&p);
    ExpectRejected(p, "exceeds the maximum");
  }
  {  // count larger than the bytes present
    std::vector<uint8_t> p = ego;
    p[kCountOffset] = 3;
    Resign(&p);
    ExpectRejected(p, "observation count 3 needs");
  }
  {  // trailing bytes after the declared observations
    std::vector<uint8_t> p = ego;
    p.insert(p.end() - kTagBytes, 1, 0);
    Resign(&p);
    ExpectRejected(p, "observation count 2 needs");
  }
  {  // NaN in a float32 field (v_bj_in_Gj.x at payload offset 56)
    std::vector<uint8_t> p = ego;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&p[kHeaderBytes + 56], &nan, 4);
    Resign(&p);
    ExpectRejected(p, "v_bj_in_Gj[0]' is not finite");
  }
  {  // Inf in a float64 field (p_bj_in_Gj.x at payload offset 32)
    std::vector<uint8_t> p = ego;
    const double inf = std::numeric_limits<double>::infinity();
    std::memcpy(&p[kHeaderBytes + 32], &inf, 8);
    Resign(&p);
    ExpectRejected(p, "p_bj_in_Gj[0]' is not finite");
  }
  {  // a non-unit quaternion (q.w at payload offset 28)
    std::vector<uint8_t> p = ego;
    const float two = 2.0f;
    std::memcpy(&p[kHeaderBytes + 28], &two, 4);
    Resign(&p);
    ExpectRejected(p, "not a unit quaternion");
  }
  {  // unknown flag bits
    std::vector<uint8_t> p = ego;
    p[kCountOffset - 1] = 0x80;
    Resign(&p);
    ExpectRejected(p, "unknown bits");
  }
  const size_t first_observation = kCountOffset + 1;
  {  // observed id out of range
    std::vector<uint8_t> p = ego;
    p[first_observation] = 200;
    Resign(&p);
    ExpectRejected(p, "observations[0].observed_id' = 200 is not a drone id");
  }
  {  // observed id equal to the sender
    std::vector<uint8_t> p = ego;
    p[first_observation] = 1;
    Resign(&p);
    ExpectRejected(p, "is the sender itself");
  }
  {  // repeated observed id
    std::vector<uint8_t> p = ego;
    p[first_observation + kObservationBytes] = p[first_observation];
    Resign(&p);
    ExpectRejected(p, "is repeated");
  }
  {  // negative variance in an observation covariance (entry (0,0))
    std::vector<uint8_t> p = ego;
    const float negative = -1.0f;
    std::memcpy(&p[first_observation + 13], &negative, 4);
    Resign(&p);
    ExpectRejected(p, "negative variance");
  }
  const std::vector<uint8_t> ext = Encode(MakeGlobalExtrinsic(0, 1, 3));
  {  // unknown extrinsic source
    std::vector<uint8_t> p = ext;
    p[kHeaderBytes + 45 + 1] = 3;  // stamp, gravity (36 B), count, id
    Resign(&p);
    ExpectRejected(p, "source': unknown value 3");
  }
  {  // entry count above the cap
    std::vector<uint8_t> p = ext;
    p[kHeaderBytes + 44] = GlobalExtrinsicMessage::kMaxEntries + 1;
    Resign(&p);
    ExpectRejected(p, "exceeds the maximum");
  }
  const std::vector<uint8_t> sync = Encode(MakeTimeSync(1, 2, false));
  {  // unknown time-sync kind
    std::vector<uint8_t> p = sync;
    p[kHeaderBytes + 1] = 2;
    Resign(&p);
    ExpectRejected(p, "kind");
  }
  {  // trailing byte
    std::vector<uint8_t> p = sync;
    p.insert(p.end() - kTagBytes, 1, 0);
    Resign(&p);
    ExpectRejected(p, "trailing bytes");
  }
}

}  // namespace
}  // namespace swarmlio::net
