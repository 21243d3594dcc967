// PacketCodec: SwarmMessage <-> authenticated packet bytes (wire_format.h).
//
//   net::PacketCodec codec;
//   SWARMLIO_RETURN_IF_ERROR(net::PacketCodec::Create(key, &codec));
//   std::vector<uint8_t> packet;
//   SWARMLIO_RETURN_IF_ERROR(codec.Encode(ego_state, sequence, &packet));
//   net::DecodedPacket decoded;
//   Status s = codec.Decode(packet.data(), packet.size(), &decoded);
//
// Decode never trusts its input. It checks, in order: size bounds, the
// header (version, type, sender id), the authentication tag (constant time),
// then every payload field (wire format version 3, docs/network.md §2-§3):
// counts against the per-type caps and the remaining bytes, ids in range and
// distinct, no NaN/Inf, every quantized code in its range, valid quaternion
// encodings, flag bits, stamp overflow, and no trailing bytes. The first failure is returned as a Status
// (DataLoss for malformed or unauthentic bytes, InvalidArgument for an
// unsupported version or type) and `*packet` is left unchanged. Encode
// applies the same field checks, so a packet that Encode produced always
// decodes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/net/swarm_key.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net {

struct DecodedPacket {
  PacketHeader header;
  SwarmMessage message;
};

class PacketCodec {
 public:
  /// A codec without a key: Encode and Decode fail with FailedPrecondition.
  PacketCodec() = default;

  /// Initialises libsodium (Internal on failure) and keeps a copy of `key`.
  static Status Create(const SwarmKey& key, PacketCodec* codec);

  /// Encodes `message` (sender = its sender_id) with `sequence` into
  /// `*packet` (replaced). InvalidArgument naming the field when the message
  /// breaks a rule that Decode checks.
  Status Encode(const SwarmMessage& message, uint32_t sequence, std::vector<uint8_t>* packet) const;

  /// Decodes and authenticates `size` bytes at `data`.
  Status Decode(const uint8_t* data, size_t size, DecodedPacket* packet) const;

 private:
  bool ready_ = false;
  SwarmKey key_;
};

/// The field checks Encode and Decode apply, for callers that build messages:
/// Ok, or InvalidArgument naming the first offending field. (Encode also
/// checks the values after rounding to float32.)
Status CheckMessage(const SwarmMessage& message);

}  // namespace swarmlio::net
