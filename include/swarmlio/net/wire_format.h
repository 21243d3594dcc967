// The swarm packet wire format, version 7 (docs/network.md, "Wire format").
//
//   offset size field
//   0      1    magic 'S' (0x53)
//   1      1    protocol version (kProtocolVersion)
//   2      1    message type (MessageType)
//   3      1    sender id (0 .. kMaxSwarmSize-1)
//   4      2    sequence number (per sender, +1 per packet, low 16 bits)
//   6      P    payload (per type, below); P = packet size - 22
//   6+P    16   tag: the first 16 bytes of HMAC-SHA512-256(swarm key, bytes [0, 6+P))
//
// All integers are little endian, floats IEEE-754 little endian, no padding.
// Version 3 quantizes the payload (resolutions and ranges below and in
// docs/network.md §2.1); every layout has a fixed size per list length, so
// the 1200-byte cap is checked by static_assert.
#pragma once

#include <cstddef>
#include <cstdint>

#include "swarmlio/net/messages.h"
#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {

inline constexpr uint8_t kMagic = 0x53;  // 'S'
/// 2: gravity in GlobalExtrinsic; 3: quantized payloads, 6-byte header, 16-byte tag;
/// 4: past observations at the end of EgoState; 5: send delay and state echoes in
/// EgoState (clock synchronisation without TimeSync packets); 6: an optional clock
/// offset report after the echoes; 7: the Airframe message (type 4).
inline constexpr uint8_t kProtocolVersion = 7;
inline constexpr size_t kHeaderBytes = 6;
inline constexpr size_t kTagBytes = 16;  // HMAC-SHA512-256 truncated to 128 bits
inline constexpr size_t kPacketOverheadBytes = kHeaderBytes + kTagBytes;

/// The decoded packet header.
struct PacketHeader {
  uint8_t version = kProtocolVersion;
  MessageType type = MessageType::kEgoState;
  int sender_id = 0;
  uint32_t sequence = 0;       // 0 .. 65535 on the wire (the sender's counter mod 2^16)
  uint16_t payload_bytes = 0;  // packet size - kPacketOverheadBytes
};

// --- Field encodings (docs/network.md §2.1) ---------------------------------
// q (unit quaternion), "smallest three": the largest |coefficient| is made
// positive and dropped (its index, 2 bits, travels in a flags byte); the
// other three, each in [-1/sqrt2, 1/sqrt2], as int16 code = round(c * kQuaternionScale).
inline constexpr int kQuaternionMaxCode = 32767;
inline constexpr double kQuaternionScale = 32767.0 * 1.4142135623730951;
// f16: IEEE binary16 (|x| <= 65504, relative rounding <= 2^-11).
// Observation position: int16 code = round(x / kObservationPositionStepM).
inline constexpr int kObservationPositionMaxCode = 32767;
inline constexpr double kObservationPositionStepM = 0.002;
inline constexpr double kObservationPositionMaxM =
    kObservationPositionMaxCode * kObservationPositionStepM;  // 65.534 m
// Covariance (N x N, symmetric): N uint8 log-variance codes, then the
// N(N-1)/2 partial correlations of the lower triangle, row by row
// ((1,0) (2,0) (2,1) (3,0) ...), as int8 codes. Decoded:
//   variance_i = 2^(kLogVarianceMin + code_i * kLogVarianceStep)
//   z_ij       = tanh(code_ij * kCorrelationStep), |code_ij| <= 127
// and the matrix is rebuilt from the partial correlations (always positive
// definite, see covariance_codec.h).
inline constexpr double kLogVarianceMin = -40.0;        // log2 of the smallest variance
inline constexpr double kLogVarianceStep = 0.25;        // log2 units per code
inline constexpr int kLogVarianceMaxCode = 255;         // largest variance 2^23.75
inline constexpr double kCorrelationStep = 1.0 / 40.0;  // atanh units per code
inline constexpr int kCorrelationMaxCode = 127;         // |z| <= tanh(127/40) = 0.99651
constexpr size_t CovarianceBytes(size_t n) { return n + n * (n - 1) / 2; }

// --- Payload layouts --------------------------------------------------------
// EgoState: stamp_ns i64 | stamp_ns - session_start_ns i48 |
//   bits u8 (0-1 q largest index, 2 degenerated, 3-7 observation count) |
//   q_Gj_bj 3 x i16 | p_bj_in_Gj f32 x3 | v_bj_in_Gj f16 x3 | omega_bj_in_bj f16 x3 |
//   cov_theta cov(3) | cov_p cov(3) | cov_v cov(3) |
//   send delay u16 (10 us; 65535 = not known) |
//   echo bits u8 (0-6 echo count 0..kMaxEchoes, 7 offset report follows (version 6)) |
//   echo count x { teammate id u8 | stamp ref u16 | its send delay u16 (10 us) |
//                  hold u16 (10 us: this packet's send time - the echoed state's arrival) } |
//   optional offset report { teammate id u8 | offset residue u16 (1 us, mod 2^16) |
//                            std u8 (50 us, 1..254) } |
//   count x { observed id u8 | p_bk_in_bj 3 x i16 (2 mm) | cov(3) } |
//   optional (version 4), present only when the message has past observations:
//   past count u8 (1..kMaxPastObservations) |
//   past count x { observed id u8 | age u16 (0.1 ms) |
//                  p_bk_in_Gj - p_bj_in_Gj 3 x i16 (2 mm) | cov(3) }
inline constexpr size_t kEgoStateFixedBytes =
    8 + 6 + 1 + 6 + 12 + 6 + 6 + 3 * CovarianceBytes(3) + 2 + 1;
inline constexpr size_t kStateEchoBytes = 1 + 2 + 2 + 2;
inline constexpr uint8_t kEchoCountMask = 0x7F;
inline constexpr uint8_t kOffsetReportFlag = 0x80;
inline constexpr size_t kOffsetReportBytes = 1 + 2 + 1;
inline constexpr int64_t kOffsetReportStepNs = 1000;      // 1 us: the residue wraps at 65.536 ms
inline constexpr int64_t kOffsetReportStdStepNs = 50000;  // 50 us: std up to 12.7 ms
// Send delay, an echo's send delay and hold: uint16 code = round(ns / kSyncDelayStepNs).
inline constexpr int64_t kSyncDelayStepNs = 10000;  // 10 us
inline constexpr int kSendDelayMaxCode = 65534;     // 655.34 ms; 65535 = not known
inline constexpr int kSendDelayUnknownCode = 65535;
inline constexpr int kHoldMaxCode = 65535;  // 655.35 ms
/// The code the writer sends for a send delay or hold (rounded; callers check the range).
constexpr int64_t SyncDelayCode(int64_t ns) {
  return (ns + kSyncDelayStepNs / 2) / kSyncDelayStepNs;
}
/// A send delay as it travels (rounded to kSyncDelayStepNs).
constexpr int64_t QuantizedSyncDelayNs(int64_t ns) { return SyncDelayCode(ns) * kSyncDelayStepNs; }
/// The hold of an echo: the send time of the state that carries it (stamp +
/// the quantized send delay) - the echoed state's arrival. False on overflow.
inline bool StateEchoHoldNs(int64_t stamp_ns,
                            int64_t send_delay_ns,
                            int64_t arrival_ns,
                            int64_t* hold_ns) {
  int64_t sent_ns = 0;
  return !__builtin_add_overflow(stamp_ns, QuantizedSyncDelayNs(send_delay_ns), &sent_ns) &&
         !__builtin_sub_overflow(sent_ns, arrival_ns, hold_ns);
}
inline constexpr size_t kObservationBytes = 1 + 6 + CovarianceBytes(3);
inline constexpr size_t kPastObservationBytes = 1 + 2 + 6 + CovarianceBytes(3);
// Past observation age: uint16 code = round(age_ns / kPastObservationAgeStepNs), 1..65535.
inline constexpr int64_t kPastObservationAgeStepNs = 100000;  // 0.1 ms
inline constexpr int kPastObservationAgeMaxCode = 65535;      // 6.5535 s
/// The age code the writer sends (rounded; callers check the range first).
constexpr int64_t PastObservationAgeCode(int64_t age_ns) {
  return (age_ns + kPastObservationAgeStepNs / 2) / kPastObservationAgeStepNs;
}
// GlobalExtrinsic: stamp i64 | g_in_Gi f32 x3 | cov_g_in_Gi cov(3) | count u8 |
//   count x { teammate id u8 | bits u8 (0-1 q largest index, 2 source: 0 trajectory
//   match, 1 graph) | q_Ga_Gb 3 x i16 | p_Gb_in_Ga f32 x3 | covariance cov(6) }
inline constexpr size_t kGlobalExtrinsicFixedBytes = 8 + 12 + CovarianceBytes(3) + 1;
inline constexpr size_t kExtrinsicEntryBytes = 1 + 1 + 6 + 12 + CovarianceBytes(6);
// TimeSync: target id u8 | kind u8 (0 request, 1 response) | t1 t2 t3 i64
inline constexpr size_t kTimeSyncBytes = 1 + 1 + 3 * 8;
// Airframe (version 7): stamp i64 | reflector shape u8 (0 band, 1 box, 2 round) |
//   min intensity u8 | reflector half extents 3 x u16 (1 mm) |
//   reflector centre in body 3 x i16 (1 mm) | depth offset u16 (1 mm) |
//   size u16 (1 mm) | centroid sigma u16 (1 mm)
// Lengths: code = round(x / kAirframeLengthStepM); non-negative ones as
// uint16 (0..65.535 m), the centre as int16 (+-32.767 m, the code -32768
// rejected); min intensity: round(x), 0..255.
inline constexpr double kAirframeLengthStepM = 0.001;
inline constexpr int kAirframeLengthMaxCode = 65535;
inline constexpr int kAirframeCentreMaxCode = 32767;
inline constexpr int kAirframeMaxShape = 2;
inline constexpr int kAirframeMaxIntensity = 255;
inline constexpr size_t kAirframeBytes = 8 + 1 + 1 + 6 + 6 + 2 + 2 + 2;

constexpr size_t EgoStatePacketBytes(size_t num_observations,
                                     size_t num_past_observations = 0,
                                     size_t num_echoes = 0,
                                     bool offset_report = false) {
  return kPacketOverheadBytes + kEgoStateFixedBytes + kStateEchoBytes * num_echoes +
         (offset_report ? kOffsetReportBytes : 0) + kObservationBytes * num_observations +
         (num_past_observations > 0 ? 1 + kPastObservationBytes * num_past_observations : 0);
}
constexpr size_t GlobalExtrinsicPacketBytes(size_t num_entries) {
  return kPacketOverheadBytes + kGlobalExtrinsicFixedBytes + kExtrinsicEntryBytes * num_entries;
}
constexpr size_t TimeSyncPacketBytes() { return kPacketOverheadBytes + kTimeSyncBytes; }
constexpr size_t AirframePacketBytes() { return kPacketOverheadBytes + kAirframeBytes; }

static_assert(kEgoStateFixedBytes == 66 && kObservationBytes == 13 && kPastObservationBytes == 15 &&
                  kStateEchoBytes == 7,
              "layout changed: update docs");
static_assert(kGlobalExtrinsicFixedBytes == 27 && kExtrinsicEntryBytes == 41,
              "layout changed: update docs");
static_assert(EgoStatePacketBytes(EgoStateMessage::kMaxObservations,
                                  EgoStateMessage::kMaxPastObservations,
                                  EgoStateMessage::kMaxEchoes,
                                  true) <= kMaxPacketBytes);
static_assert(EgoStateMessage::kMaxEchoes <= kEchoCountMask, "the echo count travels in 7 bits");
static_assert(EgoStateMessage::kMaxPastObservations <= 255, "the past count travels in one byte");
static_assert(GlobalExtrinsicPacketBytes(GlobalExtrinsicMessage::kMaxEntries) <= kMaxPacketBytes);
static_assert(TimeSyncPacketBytes() <= kMaxPacketBytes);
static_assert(kAirframeBytes == 28, "layout changed: update docs");
static_assert(EgoStateMessage::kMaxObservations < 32, "the count travels in 5 bits");
static_assert(kMaxSwarmSize <= 255, "ids travel as one byte");

}  // namespace swarmlio::net
