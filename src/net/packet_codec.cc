// PacketCodec: header, authentication tag and dispatch to the payload codecs.
#include "swarmlio/net/packet_codec.h"

#include <sodium.h>

#include <cstring>
#include <string>
#include <type_traits>

#include "src/net/packet_reader.h"
#include "src/net/packet_writer.h"
#include "src/net/payload_codecs.h"

namespace swarmlio::net {

static_assert(kTagBytes == crypto_verify_16_BYTES && kTagBytes <= crypto_auth_BYTES,
              "the tag is HMAC-SHA512-256 truncated to 128 bits");

namespace {

/// The first kTagBytes of HMAC-SHA512-256(key, data[0, size)).
void ComputeTag(const uint8_t* data, size_t size, const uint8_t* key, uint8_t* tag) {
  uint8_t full[crypto_auth_BYTES];
  crypto_auth(full, data, size, key);
  std::memcpy(tag, full, kTagBytes);
  sodium_memzero(full, sizeof(full));
}

}  // namespace

Status PacketCodec::Create(const SwarmKey& key, PacketCodec* codec) {
  if (sodium_init() < 0) return Status::Internal("libsodium failed to initialise");
  codec->key_ = key;
  codec->ready_ = true;
  return Status::Ok();
}

Status PacketCodec::Encode(const SwarmMessage& message,
                           uint32_t sequence,
                           std::vector<uint8_t>* packet) const {
  if (!ready_) return Status::FailedPrecondition("PacketCodec used before Create()");
  SWARMLIO_RETURN_IF_ERROR(CheckMessage(message));

  std::vector<uint8_t> bytes;
  bytes.reserve(kMaxPacketBytes);
  internal::PacketWriter w(&bytes);
  w.U8(kMagic);
  w.U8(kProtocolVersion);
  w.U8(static_cast<uint8_t>(TypeOf(message)));
  w.U8(static_cast<uint8_t>(SenderOf(message)));
  w.U16(static_cast<uint16_t>(sequence & 0xFFFFu));
  std::visit(
      [&w](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, EgoStateMessage>) {
          internal::EncodeEgoState(m, &w);
        } else if constexpr (std::is_same_v<T, GlobalExtrinsicMessage>) {
          internal::EncodeGlobalExtrinsic(m, &w);
        } else if constexpr (std::is_same_v<T, TimeSyncMessage>) {
          internal::EncodeTimeSync(m, &w);
        } else {
          static_assert(std::is_same_v<T, AirframeMessage>, "a message type without an encoder");
          internal::EncodeAirframe(m, &w);
        }
      },
      message);
  if (bytes.size() + kTagBytes > kMaxPacketBytes) {  // unreachable: per-type caps
    return Status::Internal("encoded packet exceeds " + std::to_string(kMaxPacketBytes) + " bytes");
  }
  const size_t signed_bytes = bytes.size();
  bytes.resize(signed_bytes + kTagBytes);
  ComputeTag(bytes.data(), signed_bytes, key_.data(), bytes.data() + signed_bytes);
  *packet = std::move(bytes);
  return Status::Ok();
}

Status PacketCodec::Decode(const uint8_t* data, size_t size, DecodedPacket* packet) const {
  if (!ready_) return Status::FailedPrecondition("PacketCodec used before Create()");
  if (size < kPacketOverheadBytes) {
    return Status::DataLoss("packet of " + std::to_string(size) +
                            " bytes is shorter than header + tag (" +
                            std::to_string(kPacketOverheadBytes) + ")");
  }
  if (size > kMaxPacketBytes) {
    return Status::DataLoss("packet of " + std::to_string(size) + " bytes exceeds the cap of " +
                            std::to_string(kMaxPacketBytes));
  }
  internal::PacketReader header_reader(data, kHeaderBytes);
  uint8_t magic = 0, version = 0, type = 0, sender = 0;
  uint16_t sequence = 0;
  PacketHeader header;
  SWARMLIO_RETURN_IF_ERROR(header_reader.U8("magic", &magic));
  SWARMLIO_RETURN_IF_ERROR(header_reader.U8("version", &version));
  SWARMLIO_RETURN_IF_ERROR(header_reader.U8("type", &type));
  SWARMLIO_RETURN_IF_ERROR(header_reader.U8("sender", &sender));
  SWARMLIO_RETURN_IF_ERROR(header_reader.U16("sequence", &sequence));
  if (magic != kMagic) return Status::DataLoss("not a swarm packet (bad magic)");
  if (version != kProtocolVersion) {
    return Status::InvalidArgument("unsupported protocol version " + std::to_string(version) +
                                   " (this build speaks " + std::to_string(kProtocolVersion) + ")");
  }
  if (type < static_cast<uint8_t>(MessageType::kEgoState) ||
      type > static_cast<uint8_t>(MessageType::kAirframe)) {
    return Status::InvalidArgument("unknown message type " + std::to_string(type));
  }
  if (!IsValidDroneId(sender)) {
    return Status::DataLoss("sender id " + std::to_string(sender) + " out of range");
  }
  const size_t signed_bytes = size - kTagBytes;
  uint8_t tag[kTagBytes];
  ComputeTag(data, signed_bytes, key_.data(), tag);
  if (crypto_verify_16(tag, data + signed_bytes) != 0) {
    return Status::DataLoss("authentication tag mismatch (wrong swarm key or corrupted packet)");
  }
  header.version = version;
  header.type = static_cast<MessageType>(type);
  header.sender_id = sender;
  header.sequence = sequence;
  header.payload_bytes = static_cast<uint16_t>(signed_bytes - kHeaderBytes);

  internal::PacketReader r(data + kHeaderBytes, header.payload_bytes);
  DecodedPacket decoded;
  decoded.header = header;
  switch (header.type) {
    case MessageType::kEgoState: {
      EgoStateMessage m;
      SWARMLIO_RETURN_IF_ERROR(internal::DecodeEgoState(sender, &r, &m).WithContext("EgoState"));
      decoded.message = std::move(m);
      break;
    }
    case MessageType::kGlobalExtrinsic: {
      GlobalExtrinsicMessage m;
      SWARMLIO_RETURN_IF_ERROR(
          internal::DecodeGlobalExtrinsic(sender, &r, &m).WithContext("GlobalExtrinsic"));
      decoded.message = std::move(m);
      break;
    }
    case MessageType::kTimeSync: {
      TimeSyncMessage m;
      SWARMLIO_RETURN_IF_ERROR(internal::DecodeTimeSync(sender, &r, &m).WithContext("TimeSync"));
      decoded.message = m;
      break;
    }
    case MessageType::kAirframe: {
      AirframeMessage m;
      SWARMLIO_RETURN_IF_ERROR(internal::DecodeAirframe(sender, &r, &m).WithContext("Airframe"));
      decoded.message = m;
      break;
    }
  }
  const Status semantic = CheckMessage(decoded.message);
  if (!semantic.ok()) return Status::DataLoss(semantic.message());
  *packet = std::move(decoded);
  return Status::Ok();
}

}  // namespace swarmlio::net
