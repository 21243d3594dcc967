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
using net_test::MakeAirframe;
using net_test::MakeCodec;
using net_test::MakeEgoState;
using net_test::MakeGlobalExtrinsic;
using net_test::MakeTimeSync;

constexpr uint64_t kKeySeed = 7;

/// Recomputes the tag after a test edited the packet, so that the header and
/// payload checks (not the tag) must catch the edit.
void Resign(std::vector<uint8_t>* packet) {
  const SwarmKey key = SwarmKey::ForSimulation(kKeySeed);
  const size_t signed_bytes = packet->size() - kTagBytes;
  uint8_t full[crypto_auth_BYTES];
  crypto_auth(full, packet->data(), signed_bytes, key.data());
  std::memcpy(packet->data() + signed_bytes, full, kTagBytes);
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
    const std::vector<uint8_t> original = Encode(messages[trial % messages.size()]);
    std::vector<uint8_t> packet = original;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) {
      const size_t at = rng() % packet.size();
      packet[at] ^= static_cast<uint8_t>(1 + rng() % 255);  // never a no-op on its own
    }
    if (packet == original) continue;  // two flips of one byte cancelled out
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
      bytes[0] = kMagic;
      bytes[1] = kProtocolVersion;
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
  p[1] = kProtocolVersion + 1;
  EXPECT_EQ(Decode(p).code(), Status::Code::kInvalidArgument);
  ExpectRejected(p, "unsupported protocol version " + std::to_string(kProtocolVersion + 1));
  p[1] = 'L';  // a version 1/2 packet: 'S' 'L' version ...
  ExpectRejected(p, "unsupported protocol version 76");
  p = good;
  p[2] = 9;
  ExpectRejected(p, "unknown message type 9");
  p = good;
  p[2] = 0;
  ExpectRejected(p, "unknown message type 0");
  p = good;
  p[3] = kMaxSwarmSize;
  ExpectRejected(p, "sender id 64");
  p = good;  // checks before the tag only need the header: a header-only packet
  p.resize(kPacketOverheadBytes - 1);
  ExpectRejected(p, "shorter than header + tag");
  std::vector<uint8_t> huge(kMaxPacketBytes + 1, 0);
  ExpectRejected(huge, "exceeds the cap");
  // The header is authenticated: any edit that passes the checks fails the tag.
  p = good;
  p[3] = 2;  // another sender
  ExpectRejected(p, "authentication tag mismatch");
  p = good;
  p[4] ^= 1;  // another sequence number
  ExpectRejected(p, "authentication tag mismatch");
}

/// Payload offsets of the EgoState fields (wire_format.h).
constexpr size_t kEgoBits = kHeaderBytes + 14;
constexpr size_t kEgoQuaternion = kHeaderBytes + 15;
constexpr size_t kEgoPosition = kHeaderBytes + 21;
constexpr size_t kEgoVelocity = kHeaderBytes + 33;
constexpr size_t kEgoOmega = kHeaderBytes + 39;
constexpr size_t kEgoCovP = kHeaderBytes + 51;
constexpr size_t kEgoFirstEcho = kHeaderBytes + kEgoStateFixedBytes;

void PutU16(std::vector<uint8_t>* p, size_t at, uint16_t value) {
  (*p)[at] = static_cast<uint8_t>(value & 0xFF);
  (*p)[at + 1] = static_cast<uint8_t>(value >> 8);
}

void SetCount(std::vector<uint8_t>* p, int count) {
  (*p)[kEgoBits] = static_cast<uint8_t>(((*p)[kEgoBits] & 0x07) | (count << 3));
}

TEST(PacketCodecRobustness, AuthenticatedButMalformedPayloadsAreRejected) {
  const std::vector<uint8_t> ego = Encode(MakeEgoState(1, 2, 5));
  {  // sanity: Resign alone keeps a packet valid, and the count is where we think
    std::vector<uint8_t> p = ego;
    Resign(&p);
    EXPECT_TRUE(Decode(p).ok());
    EXPECT_EQ(p[kEgoBits] >> 3, 2);
  }
  {  // over-long list: a count above the cap, with the bytes present
    std::vector<uint8_t> p = Encode(MakeEgoState(1, EgoStateMessage::kMaxObservations, 5));
    p.insert(p.end() - kTagBytes, kObservationBytes, 0);
    SetCount(&p, EgoStateMessage::kMaxObservations + 1);
    Resign(&p);
    ExpectRejected(p, "observation count 25 exceeds the maximum 24");
  }
  {  // count larger than the bytes present
    std::vector<uint8_t> p = ego;
    SetCount(&p, 3);
    Resign(&p);
    ExpectRejected(p, "observation count 3 needs");
  }
  {  // trailing bytes after the declared observations: read as a past-observation count
    std::vector<uint8_t> p = ego;
    p.insert(p.end() - kTagBytes, 1, 0);
    Resign(&p);
    ExpectRejected(p, "past observation count 0 (1..24) does not match the 0 bytes after it");
  }
  {  // past observations: count against the bytes, the cap, a zero age, the sender's own id
    const std::vector<uint8_t> past = Encode(MakeEgoState(1, 2, 5, 2));
    const size_t count_at = kEgoFirstEcho + 2 * kObservationBytes;  // no echoes
    std::vector<uint8_t> p = past;
    Resign(&p);
    ASSERT_TRUE(Decode(p).ok());
    ASSERT_EQ(p[count_at], 2);
    p[count_at] = 3;
    Resign(&p);
    ExpectRejected(p, "past observation count 3 (1..24) does not match the 30 bytes after it");
    p = past;
    p.insert(p.end() - kTagBytes, 1, 0);  // one trailing byte
    Resign(&p);
    ExpectRejected(p, "past observation count 2 (1..24) does not match the 31 bytes after it");
    p = past;
    p[count_at] = 25;
    p.insert(p.end() - kTagBytes, 23 * kPastObservationBytes, 0);
    Resign(&p);
    ExpectRejected(p, "past observation count 25 (1..24)");
    p = past;
    PutU16(&p, count_at + 2, 0);  // the first entry's age
    Resign(&p);
    ExpectRejected(p, "past_observations[0]: field 'age' is 0");
    p = past;
    p[count_at + 1] = 1;  // the first entry observed the sender itself
    Resign(&p);
    ExpectRejected(p, "past_observations[0].observed_id' = 1 is the sender itself");
  }
  {  // clock echoes: the cap, an unknown send delay, the sender's own id, a bad delay code,
     // a count larger than the bytes
    const std::vector<uint8_t> echo = Encode(MakeEgoState(1, 2, 5, 0, 2));
    const size_t delay_at = kEgoFirstEcho - 3;
    const size_t count_at = kEgoFirstEcho - 1;
    std::vector<uint8_t> p = echo;
    Resign(&p);
    ASSERT_TRUE(Decode(p).ok());
    ASSERT_EQ(p[count_at], 2);
    p[count_at] = EgoStateMessage::kMaxEchoes + 1;
    p.insert(p.end() - kTagBytes, (EgoStateMessage::kMaxEchoes - 1) * kStateEchoBytes, 0);
    Resign(&p);
    ExpectRejected(p, "echo count 9 exceeds the maximum 8");
    p = echo;
    PutU16(&p, delay_at, 65535);
    Resign(&p);
    ExpectRejected(p, "echo count 2 with an unknown send delay");
    p = echo;
    p[kEgoFirstEcho] = 1;  // the first echo names the sender itself
    Resign(&p);
    ExpectRejected(p, "echoes[0].teammate_id' = 1 is the sender itself");
    p = echo;
    PutU16(&p, kEgoFirstEcho + 3, 65535);  // the first echo's send delay
    Resign(&p);
    ExpectRejected(p, "echoes[0]: send delay code 65535 is not a known delay");
    p = echo;
    p[count_at] = 3;
    Resign(&p);
    ExpectRejected(p, "observation count 2 needs");
  }
  {  // an offset report: flagged but missing, a bad std code, the sender's own id, an
     // unknown send delay
    EgoStateMessage m = MakeEgoState(1, 0, 6, 0, 1);
    m.offset_report = ClockOffsetReport{2, 1234, 20};
    const std::vector<uint8_t> report = Encode(m);
    const size_t count_at = kEgoFirstEcho - 1;
    const size_t report_at = kEgoFirstEcho + kStateEchoBytes;
    std::vector<uint8_t> p = report;
    Resign(&p);
    ASSERT_TRUE(Decode(p).ok());
    ASSERT_EQ(p[count_at], kOffsetReportFlag | 1);
    p.erase(p.begin() + static_cast<std::ptrdiff_t>(report_at),
            p.begin() + static_cast<std::ptrdiff_t>(report_at + kOffsetReportBytes));
    Resign(&p);
    ExpectRejected(p, "needs");
    p = report;
    p[report_at + 3] = 0;
    Resign(&p);
    ExpectRejected(p, "offset report: std code 0 is outside [1, 254]");
    p = report;
    p[report_at + 3] = 255;
    Resign(&p);
    ExpectRejected(p, "offset report: std code 255 is outside [1, 254]");
    p = report;
    p[report_at] = 1;
    Resign(&p);
    ExpectRejected(p, "offset_report.teammate_id' = 1 is the sender itself");
    p = report;
    PutU16(&p, kEgoFirstEcho - 3, 65535);
    Resign(&p);
    ExpectRejected(p, "with an unknown send delay");
  }
  {  // a payload shorter than the fixed part
    std::vector<uint8_t> p = ego;
    p.erase(p.begin() + kHeaderBytes + 20, p.end() - kTagBytes);
    Resign(&p);
    ExpectRejected(p, "needs");
  }
  {  // NaN in a float32 field
    std::vector<uint8_t> p = ego;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&p[kEgoPosition + 4], &nan, 4);
    Resign(&p);
    ExpectRejected(p, "p_bj_in_Gj[1]' is not finite");
  }
  {  // Inf and NaN in float16 fields
    std::vector<uint8_t> p = ego;
    PutU16(&p, kEgoVelocity, 0x7C00);
    Resign(&p);
    ExpectRejected(p, "v_bj_in_Gj[0]' is not finite");
    p = ego;
    PutU16(&p, kEgoOmega + 4, 0xFE00);
    Resign(&p);
    ExpectRejected(p, "omega_bj_in_bj[2]' is not finite");
  }
  {  // quaternion codes that are not a canonical smallest-three encoding
    std::vector<uint8_t> p = ego;
    for (int i = 0; i < 3; ++i) PutU16(&p, kEgoQuaternion + 2 * i, 32767);  // sum c^2 = 1.5
    Resign(&p);
    ExpectRejected(p, "q_Gj_bj' is not a canonical smallest-three code");
    p = ego;
    PutU16(&p, kEgoQuaternion + 2, 0x8000);  // -32768
    Resign(&p);
    ExpectRejected(p, "q_Gj_bj' is not a canonical smallest-three code");
  }
  {  // correlation code -128 (cov_p's third code is its first correlation)
    std::vector<uint8_t> p = ego;
    p[kEgoCovP + 3] = 0x80;
    Resign(&p);
    ExpectRejected(p, "cov_p_bj_in_Gj[3]' has the out-of-range correlation code -128");
  }
  {  // stamps: an overflowing session start, a negative stamp, a negative session start
    std::vector<uint8_t> p = ego;  // stamp_ns = INT64_MIN, stamp - session > 0
    for (int i = 0; i < 8; ++i) p[kHeaderBytes + i] = i == 7 ? 0x80 : 0x00;
    Resign(&p);
    ExpectRejected(p, "session_start_ns' overflows int64");
    p = ego;  // stamp_ns = -1
    for (int i = 0; i < 8; ++i) p[kHeaderBytes + i] = 0xFF;
    Resign(&p);
    ExpectRejected(p, "stamp_ns' is negative");
    p = ego;  // stamp_ns = 5, before the session offset
    for (int i = 0; i < 8; ++i) p[kHeaderBytes + i] = i == 0 ? 5 : 0;
    Resign(&p);
    ExpectRejected(p, "session_start_ns' is negative");
  }
  const size_t first = kEgoFirstEcho;  // the first observation (no echoes)
  {                                    // observed id out of range
    std::vector<uint8_t> p = ego;
    p[first] = 200;
    Resign(&p);
    ExpectRejected(p, "observations[0].observed_id' = 200 is not a drone id");
  }
  {  // observed id equal to the sender
    std::vector<uint8_t> p = ego;
    p[first] = 1;
    Resign(&p);
    ExpectRejected(p, "is the sender itself");
  }
  {  // repeated observed id
    std::vector<uint8_t> p = ego;
    p[first + kObservationBytes] = p[first];
    Resign(&p);
    ExpectRejected(p, "is repeated");
  }
  {  // observation position code -32768
    std::vector<uint8_t> p = ego;
    PutU16(&p, first + 1 + 2, 0x8000);
    Resign(&p);
    ExpectRejected(p, "observations[0]: field 'p_bk_in_bj[1]' has the out-of-range code -32768");
  }
  const std::vector<uint8_t> ext = Encode(MakeGlobalExtrinsic(0, 1, 3));
  const size_t count_at = kHeaderBytes + kGlobalExtrinsicFixedBytes - 1;
  {  // unknown bits in an entry
    std::vector<uint8_t> p = ext;
    p[count_at + 2] |= 0x80;  // count, id, bits
    Resign(&p);
    ExpectRejected(p, "entries[0]: field 'bits': unknown bits set");
  }
  {  // entry count above the cap
    std::vector<uint8_t> p = ext;
    p[count_at] = GlobalExtrinsicMessage::kMaxEntries + 1;
    Resign(&p);
    ExpectRejected(p, "exceeds the maximum");
  }
  {  // a correlation code -128 in the 6x6 covariance (its last code)
    std::vector<uint8_t> p = ext;
    p[p.size() - kTagBytes - 1] = 0x80;
    Resign(&p);
    ExpectRejected(p, "entries[0]: field 'covariance[20]' has the out-of-range correlation code");
  }
  {  // entry teammate id equal to the sender
    std::vector<uint8_t> p = ext;
    p[count_at + 1] = 0;
    Resign(&p);
    ExpectRejected(p, "is the sender itself");
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

/// Payload offsets of the Airframe fields (wire_format.h).
constexpr size_t kAirframeShape = kHeaderBytes + 8;
constexpr size_t kAirframeCentre = kHeaderBytes + 16;

TEST(PacketCodecRobustness, MalformedAirframesAreRejected) {
  const std::vector<uint8_t> airframe = Encode(MakeAirframe(4, 302));
  {  // sanity: Resign alone keeps the packet valid, and the shape is where we think
    std::vector<uint8_t> p = airframe;
    Resign(&p);
    ASSERT_TRUE(Decode(p).ok());
    EXPECT_EQ(p[kAirframeShape], 2);  // seed 302: round
  }
  for (uint8_t shape : {3, 255}) {  // unknown shapes
    std::vector<uint8_t> p = airframe;
    p[kAirframeShape] = shape;
    Resign(&p);
    ExpectRejected(
        p, "Airframe: field 'reflector_shape' has the unknown value " + std::to_string(shape));
  }
  {  // a centre code of -32768 (the range is +-32767 mm)
    std::vector<uint8_t> p = airframe;
    PutU16(&p, kAirframeCentre + 2, 0x8000);
    Resign(&p);
    ExpectRejected(p, "field 'reflector_centre_in_body_m[1]' has the out-of-range code -32768");
  }
  {  // a negative stamp
    std::vector<uint8_t> p = airframe;
    for (int i = 0; i < 8; ++i) p[kHeaderBytes + i] = 0xFF;
    Resign(&p);
    ExpectRejected(p, "Airframe: field 'stamp_ns' is negative");
  }
  {  // one byte short, one byte too many
    std::vector<uint8_t> p = airframe;
    p.erase(p.end() - kTagBytes - 1);
    Resign(&p);
    ExpectRejected(p, "truncated reading field 'centroid_sigma_m'");
    p = airframe;
    p.insert(p.end() - kTagBytes, 1, 0);
    Resign(&p);
    ExpectRejected(p, "trailing bytes");
  }
  {  // another type's payload under the Airframe type, and the reverse
    std::vector<uint8_t> p = Encode(MakeTimeSync(1, 2, false));
    p[2] = static_cast<uint8_t>(MessageType::kAirframe);
    Resign(&p);
    ExpectRejected(p, "Airframe");
    p = airframe;
    p[2] = static_cast<uint8_t>(MessageType::kTimeSync);
    Resign(&p);
    EXPECT_FALSE(Decode(p).ok());
  }
}

}  // namespace
}  // namespace swarmlio::net
