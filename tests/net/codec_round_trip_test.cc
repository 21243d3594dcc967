// Round trips, sizes and the header layout of the packet codec.
#include <gtest/gtest.h>
#include <sodium.h>

#include <cmath>
#include <limits>

#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/wire_format.h"
#include "tests/net/net_test_util.h"

namespace swarmlio::net {
namespace {

using net_test::AllExampleMessages;
using net_test::ExpectSameMessage;
using net_test::MakeAirframe;
using net_test::MakeCodec;
using net_test::MakeEgoState;
using net_test::MakeGlobalExtrinsic;
using net_test::MakeRawAirframe;
using net_test::MakeTimeSync;

size_t ExpectedPacketBytes(const SwarmMessage& m) {
  if (const auto* e = std::get_if<EgoStateMessage>(&m)) {
    return EgoStatePacketBytes(e->observations.size(), e->past_observations.size(),
                               e->echoes.size(), e->offset_report.has_value());
  }
  if (const auto* g = std::get_if<GlobalExtrinsicMessage>(&m)) {
    return GlobalExtrinsicPacketBytes(g->entries.size());
  }
  if (std::holds_alternative<AirframeMessage>(m)) return AirframePacketBytes();
  return TimeSyncPacketBytes();
}

TEST(PacketCodec, EveryMessageRoundTripsBitExactly) {
  const PacketCodec codec = MakeCodec();
  uint32_t sequence = 0xFFFFFFF0u;  // also exercises the high bytes
  for (const SwarmMessage& message : AllExampleMessages()) {
    SCOPED_TRACE(MessageTypeName(TypeOf(message)));
    std::vector<uint8_t> packet;
    ASSERT_TRUE(codec.Encode(message, sequence, &packet).ok());
    EXPECT_EQ(packet.size(), ExpectedPacketBytes(message));
    EXPECT_LE(packet.size(), kMaxPacketBytes);

    DecodedPacket decoded;
    const Status s = codec.Decode(packet.data(), packet.size(), &decoded);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(decoded.header.version, kProtocolVersion);
    EXPECT_EQ(decoded.header.type, TypeOf(message));
    EXPECT_EQ(decoded.header.sender_id, SenderOf(message));
    EXPECT_EQ(decoded.header.sequence, sequence & 0xFFFFu);  // 16 bits on the wire
    EXPECT_EQ(decoded.header.payload_bytes, packet.size() - kPacketOverheadBytes);
    ExpectSameMessage(message, decoded.message);

    std::vector<uint8_t> again;
    ASSERT_TRUE(codec.Encode(decoded.message, sequence, &again).ok());
    EXPECT_EQ(again, packet);
    ++sequence;
  }
}

TEST(PacketCodec, DocumentedSizes) {
  // docs/network.md, "Messages and their sizes".
  EXPECT_EQ(kPacketOverheadBytes, 22u);
  EXPECT_EQ(EgoStatePacketBytes(0), 88u);
  EXPECT_EQ(EgoStatePacketBytes(1), 101u);
  EXPECT_EQ(EgoStatePacketBytes(2), 114u);
  EXPECT_EQ(EgoStatePacketBytes(4), 140u);
  EXPECT_EQ(EgoStatePacketBytes(EgoStateMessage::kMaxObservations), 400u);
  EXPECT_EQ(EgoStatePacketBytes(1, 1), 117u);          // one observation, repeated in the next
  EXPECT_EQ(EgoStatePacketBytes(1, 0, 1), 108u);       // one observation, one clock echo
  EXPECT_EQ(EgoStatePacketBytes(0, 0, 0, true), 92u);  // an offset report
  EXPECT_EQ(EgoStatePacketBytes(EgoStateMessage::kMaxObservations,
                                EgoStateMessage::kMaxPastObservations, EgoStateMessage::kMaxEchoes),
            817u);
  EXPECT_EQ(GlobalExtrinsicPacketBytes(0), 49u);
  EXPECT_EQ(GlobalExtrinsicPacketBytes(1), 90u);
  EXPECT_EQ(GlobalExtrinsicPacketBytes(GlobalExtrinsicMessage::kMaxEntries), 377u);
  EXPECT_EQ(TimeSyncPacketBytes(), 48u);
  EXPECT_EQ(AirframePacketBytes(), 50u);
}

// Lengths travel in millimetre steps, the intensity in whole units: decoded
// within half a step of what was sent, for every shape.
TEST(PacketCodec, AirframeRoundTripsWithinTheQuantization) {
  const PacketCodec codec = MakeCodec();
  for (uint64_t seed = 0; seed < 300; ++seed) {
    const AirframeMessage m = MakeRawAirframe(static_cast<int>(seed % 64), seed);
    std::vector<uint8_t> packet;
    ASSERT_TRUE(codec.Encode(m, 0, &packet).ok());
    ASSERT_EQ(packet.size(), AirframePacketBytes());
    DecodedPacket decoded;
    const Status s = codec.Decode(packet.data(), packet.size(), &decoded);
    ASSERT_TRUE(s.ok()) << s.message();
    const auto& d = std::get<AirframeMessage>(decoded.message);
    constexpr double kHalfStepM = 0.5 * kAirframeLengthStepM + 1e-12;
    EXPECT_EQ(d.sender_id, m.sender_id);
    EXPECT_EQ(d.stamp_ns, m.stamp_ns);
    EXPECT_EQ(d.reflector_shape, m.reflector_shape);
    EXPECT_LE((d.reflector_half_extents_m - m.reflector_half_extents_m).cwiseAbs().maxCoeff(),
              kHalfStepM);
    EXPECT_LE((d.reflector_centre_in_body_m - m.reflector_centre_in_body_m).cwiseAbs().maxCoeff(),
              kHalfStepM);
    EXPECT_LE(std::abs(d.depth_offset_m - m.depth_offset_m), kHalfStepM);
    EXPECT_LE(std::abs(d.size_m - m.size_m), kHalfStepM);
    EXPECT_LE(std::abs(d.centroid_sigma_m - m.centroid_sigma_m), kHalfStepM);
    EXPECT_LE(std::abs(d.min_intensity - m.min_intensity), 0.5);
    EXPECT_EQ(d.min_intensity, std::round(d.min_intensity));
  }
  // The ends of the wire ranges.
  AirframeMessage m = MakeRawAirframe(1, 7);
  m.reflector_half_extents_m = {0.0, 65.535, 0.0};
  m.reflector_centre_in_body_m = {-32.767, 32.767, 0.0};
  m.min_intensity = 255.0;
  std::vector<uint8_t> packet;
  ASSERT_TRUE(codec.Encode(m, 0, &packet).ok());
  DecodedPacket decoded;
  ASSERT_TRUE(codec.Decode(packet.data(), packet.size(), &decoded).ok());
  const auto& d = std::get<AirframeMessage>(decoded.message);
  EXPECT_NEAR(d.reflector_half_extents_m.y(), 65.535, 1e-9);
  EXPECT_NEAR(d.reflector_centre_in_body_m.x(), -32.767, 1e-9);
  EXPECT_EQ(d.min_intensity, 255.0);
}

TEST(PacketCodec, HeaderIsLittleEndianAndPacked) {
  const PacketCodec codec = MakeCodec();
  std::vector<uint8_t> packet;
  ASSERT_TRUE(codec.Encode(MakeTimeSync(5, 9, false), 0x04030201u, &packet).ok());
  ASSERT_EQ(packet.size(), TimeSyncPacketBytes());
  const std::vector<uint8_t> header(packet.begin(), packet.begin() + kHeaderBytes);
  const std::vector<uint8_t> expected = {'S', kProtocolVersion, 3, 5, 0x01, 0x02};
  EXPECT_EQ(header, expected);
  // Payload: target, kind, then t1 little endian.
  EXPECT_EQ(packet[6], 9);
  EXPECT_EQ(packet[7], 0);
  const int64_t t1 = 1'000'000'123;
  for (int i = 0; i < 8; ++i) EXPECT_EQ(packet[8 + i], static_cast<uint8_t>(t1 >> (8 * i)));
}

TEST(PacketCodec, TagIsTruncatedHmacSha512256) {
  const PacketCodec codec = MakeCodec(7);
  std::vector<uint8_t> packet;
  ASSERT_TRUE(codec.Encode(MakeEgoState(2, 1, 4), 9, &packet).ok());
  const SwarmKey key = SwarmKey::ForSimulation(7);
  uint8_t full[crypto_auth_BYTES];
  crypto_auth(full, packet.data(), packet.size() - kTagBytes, key.data());
  const std::vector<uint8_t> tag(packet.end() - kTagBytes, packet.end());
  EXPECT_EQ(tag, std::vector<uint8_t>(full, full + kTagBytes));
}

TEST(PacketCodec, EncodeRejectsInvalidMessages) {
  const PacketCodec codec = MakeCodec();
  std::vector<uint8_t> packet;
  auto expect_rejected = [&](const SwarmMessage& m, const std::string& field) {
    const Status s = codec.Encode(m, 0, &packet);
    EXPECT_EQ(s.code(), Status::Code::kInvalidArgument) << field;
    EXPECT_NE(s.message().find(field), std::string::npos) << s.message();
  };
  EgoStateMessage e = MakeEgoState(2, 2, 1);
  e.v_bj_in_Gj.x() = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(e, "v_bj_in_Gj[0]");
  e = MakeEgoState(2, 2, 1);
  e.omega_bj_in_bj.z() = 65520.0;  // rounds to Inf in float16
  expect_rejected(e, "omega_bj_in_bj[2]");
  e = MakeEgoState(2, 2, 1);
  e.v_bj_in_Gj.y() = -1e5;
  expect_rejected(e, "v_bj_in_Gj[1]");
  e = MakeEgoState(2, 2, 1);
  e.p_bj_in_Gj.x() = 1e39;  // overflows float32
  expect_rejected(e, "p_bj_in_Gj[0]");
  e = MakeEgoState(2, 2, 1);
  e.observations[1].p_bk_in_bj.z() = 65.6;  // beyond +-65.534 m
  expect_rejected(e, "observations[1].p_bk_in_bj[2]");
  e = MakeEgoState(2, 2, 1);
  e.cov_p_bj_in_Gj(1, 1) = 1e8;  // above 2^23.875
  expect_rejected(e, "cov_p_bj_in_Gj' has a variance above the wire range");
  e = MakeEgoState(2, 2, 1);
  e.cov_theta_Gj_bj(0, 2) = std::numeric_limits<double>::infinity();
  expect_rejected(e, "cov_theta_Gj_bj' is not finite");
  e = MakeEgoState(2, 2, 1);
  e.session_start_ns = e.stamp_ns - (int64_t{1} << 47);  // 39 h before
  expect_rejected(e, "session_start_ns");
  e = MakeEgoState(2, 2, 1);
  e.p_bj_in_Gj.y() = std::numeric_limits<double>::infinity();
  expect_rejected(e, "p_bj_in_Gj[1]");
  e = MakeEgoState(2, 2, 1);
  e.q_Gj_bj.coeffs() *= 1.01;
  expect_rejected(e, "q_Gj_bj");
  e = MakeEgoState(2, 2, 1);
  e.cov_v_bj_in_Gj(2, 2) = -1e-3;
  expect_rejected(e, "cov_v_bj_in_Gj");
  e = MakeEgoState(64, 0, 1);
  expect_rejected(e, "sender_id");
  e = MakeEgoState(2, 2, 1);
  e.observations[1].observed_id = e.observations[0].observed_id;
  expect_rejected(e, "observations[1].observed_id");
  e = MakeEgoState(2, 2, 1);
  e.observations[0].observed_id = 2;
  expect_rejected(e, "observations[0].observed_id");
  e = MakeEgoState(2, EgoStateMessage::kMaxObservations + 1, 1);
  expect_rejected(e, "observations");
  e = MakeEgoState(2, 0, 1);
  e.stamp_ns = -1;
  expect_rejected(e, "stamp_ns");

  GlobalExtrinsicMessage g = MakeGlobalExtrinsic(0, GlobalExtrinsicMessage::kMaxEntries + 1, 1);
  expect_rejected(g, "SplitGlobalExtrinsics");
  g = MakeGlobalExtrinsic(0, 1, 1);
  g.entries[0].source = static_cast<ExtrinsicSource>(7);
  expect_rejected(g, "entries[0].source");
  g = MakeGlobalExtrinsic(0, 1, 1);
  g.entries[0].teammate_id = -1;
  expect_rejected(g, "entries[0].teammate_id");

  TimeSyncMessage t = MakeTimeSync(1, 1, false);
  expect_rejected(t, "target_id");
  t = MakeTimeSync(1, 2, false);
  t.t2_ns = 5;
  expect_rejected(t, "t2_ns");

  AirframeMessage a = MakeAirframe(4, 1);
  a.reflector_shape = 3;
  expect_rejected(a, "reflector_shape");
  a = MakeAirframe(4, 1);
  a.reflector_half_extents_m.z() = -0.001;
  expect_rejected(a, "reflector_half_extents_m[2]' = -0.001000 m is outside the wire range");
  a = MakeAirframe(4, 1);
  a.reflector_centre_in_body_m.y() = 40.0;  // beyond +-32.767 m
  expect_rejected(a, "reflector_centre_in_body_m[1]");
  a = MakeAirframe(4, 1);
  a.size_m = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(a, "size_m");
  a = MakeAirframe(4, 1);
  a.depth_offset_m = 65.536;  // beyond the uint16 code
  expect_rejected(a, "depth_offset_m");
  a = MakeAirframe(4, 1);
  a.min_intensity = 256.0;
  expect_rejected(a, "min_intensity");
  a = MakeAirframe(4, 1);
  a.stamp_ns = -1;
  expect_rejected(a, "stamp_ns");
}

TEST(PacketCodec, UncreatedCodecFails) {
  const PacketCodec codec;
  std::vector<uint8_t> packet;
  EXPECT_EQ(codec.Encode(MakeTimeSync(0, 1, false), 0, &packet).code(),
            Status::Code::kFailedPrecondition);
  DecodedPacket decoded;
  EXPECT_EQ(codec.Decode(packet.data(), packet.size(), &decoded).code(),
            Status::Code::kFailedPrecondition);
}

TEST(SplitGlobalExtrinsics, ChunksAtTheCap) {
  const auto entries = MakeGlobalExtrinsic(0, 20, 5).entries;
  const auto messages = SplitGlobalExtrinsics(0, 77, entries);
  ASSERT_EQ(messages.size(), 3u);
  EXPECT_EQ(messages[0].entries.size(), 8u);
  EXPECT_EQ(messages[1].entries.size(), 8u);
  EXPECT_EQ(messages[2].entries.size(), 4u);
  EXPECT_EQ(messages[2].entries[3].teammate_id, entries[19].teammate_id);
  EXPECT_EQ(messages[1].stamp_ns, 77);
  const PacketCodec codec = MakeCodec();
  for (const auto& m : messages) {
    std::vector<uint8_t> packet;
    EXPECT_TRUE(codec.Encode(m, 0, &packet).ok());
  }
  const auto none = SplitGlobalExtrinsics(4, 1, {});
  ASSERT_EQ(none.size(), 1u);
  EXPECT_TRUE(none[0].entries.empty());
}

TEST(SwarmKey, FromHex) {
  SwarmKey key;
  const std::string hex = "  00112233445566778899aabbccddeeff00112233445566778899AABBCCDDEEFF\n";
  ASSERT_TRUE(SwarmKey::FromHex(hex, &key).ok());
  EXPECT_EQ(key.data()[1], 0x11);
  EXPECT_EQ(key.data()[31], 0xFF);
  EXPECT_FALSE(SwarmKey::FromHex("0011", &key).ok());
  EXPECT_FALSE(SwarmKey::FromHex(std::string(63, '0') + "g", &key).ok());
  const uint8_t short_key[3] = {1, 2, 3};
  EXPECT_FALSE(SwarmKey::FromBytes(short_key, sizeof(short_key), &key).ok());
}

}  // namespace
}  // namespace swarmlio::net
