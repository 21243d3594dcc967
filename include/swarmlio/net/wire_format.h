// The swarm packet wire format, version 2 (docs/network.md, "Wire format").
//
//   offset size field
//   0      2    magic 'S' 'L' (0x53 0x4C)
//   2      1    protocol version (kProtocolVersion)
//   3      1    message type (MessageType)
//   4      1    sender id (0 .. kMaxSwarmSize-1)
//   5      1    flags (reserved, must be 0)
//   6      4    sequence number (per sender, +1 per packet)
//   10     2    payload length P
//   12     P    payload (per type, below)
//   12+P   32   tag: HMAC-SHA512-256(swarm key, bytes [0, 12+P))
//
// All integers are little endian, floats IEEE-754 little endian, no padding.
// Payload sizes are compile-time functions of the list lengths so that the
// 1200-byte cap is checked by static_assert.
#pragma once

#include <cstddef>
#include <cstdint>

#include "swarmlio/net/messages.h"
#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {

inline constexpr uint8_t kMagic0 = 0x53;  // 'S'
inline constexpr uint8_t kMagic1 = 0x4C;  // 'L'
inline constexpr uint8_t kProtocolVersion = 2;  // 2: gravity in GlobalExtrinsic
inline constexpr size_t kHeaderBytes = 12;
inline constexpr size_t kTagBytes = 32;  // crypto_auth_hmacsha512256_BYTES
inline constexpr size_t kPacketOverheadBytes = kHeaderBytes + kTagBytes;

/// The decoded packet header.
struct PacketHeader {
  uint8_t version = kProtocolVersion;
  MessageType type = MessageType::kEgoState;
  int sender_id = 0;
  uint32_t sequence = 0;
  uint16_t payload_bytes = 0;
};

// --- Payload layouts --------------------------------------------------------
// EgoState: stamp i64 | session_start i64 | q_Gj_bj f32x4 (x y z w) |
//   p_bj_in_Gj f64x3 | v_bj_in_Gj f32x3 | omega_bj_in_bj f32x3 |
//   cov_theta f32x6 | cov_p f32x6 | cov_v f32x6 | flags u8 (bit0 degenerated) |
//   count u8 | count x { observed id u8 | p_bk_in_bj f32x3 | cov f32x6 }
inline constexpr size_t kEgoStateFixedBytes = 8 + 8 + 16 + 24 + 12 + 12 + 3 * 24 + 1 + 1;
inline constexpr size_t kObservationBytes = 1 + 12 + 24;
// GlobalExtrinsic: stamp i64 | g_in_Gi f32x3 | cov_g_in_Gi f32x6 | count u8 |
//   count x { teammate id u8 | source u8 | q_Gi_Gj f32x4 | p_Gj_in_Gi f64x3 |
//   covariance upper triangle f32x21 }
inline constexpr size_t kGlobalExtrinsicFixedBytes = 8 + 12 + 24 + 1;
inline constexpr size_t kExtrinsicEntryBytes = 1 + 1 + 16 + 24 + 21 * 4;
// TimeSync: target id u8 | kind u8 (0 request, 1 response) | t1 t2 t3 i64
inline constexpr size_t kTimeSyncBytes = 1 + 1 + 3 * 8;

constexpr size_t EgoStatePacketBytes(size_t num_observations) {
  return kPacketOverheadBytes + kEgoStateFixedBytes + kObservationBytes * num_observations;
}
constexpr size_t GlobalExtrinsicPacketBytes(size_t num_entries) {
  return kPacketOverheadBytes + kGlobalExtrinsicFixedBytes + kExtrinsicEntryBytes * num_entries;
}
constexpr size_t TimeSyncPacketBytes() { return kPacketOverheadBytes + kTimeSyncBytes; }

static_assert(kEgoStateFixedBytes == 154 && kObservationBytes == 37, "layout changed: update docs");
static_assert(kExtrinsicEntryBytes == 126, "layout changed: update docs");
static_assert(EgoStatePacketBytes(EgoStateMessage::kMaxObservations) <= kMaxPacketBytes);
static_assert(GlobalExtrinsicPacketBytes(GlobalExtrinsicMessage::kMaxEntries) <= kMaxPacketBytes);
static_assert(TimeSyncPacketBytes() <= kMaxPacketBytes);
static_assert(kMaxSwarmSize <= 255, "ids travel as one byte");

}  // namespace swarmlio::net
