// Payload encoders and decoders, one pair per message type (the packet
// header and tag are handled by packet_codec.cc). Encoders assume the message
// passed CheckMessage; decoders check sizes, counts and finiteness while
// reading, and leave semantic checks (ids, quaternions, variances) to
// CheckMessage.
#pragma once

#include <cstdint>
#include <vector>

#include "src/net/packet_reader.h"
#include "src/net/packet_writer.h"
#include "swarmlio/common/status.h"
#include "swarmlio/net/messages.h"

namespace swarmlio::net::internal {

void EncodeEgoState(const EgoStateMessage& message, PacketWriter* w);
/// `sender_id` comes from the packet header.
Status DecodeEgoState(int sender_id, PacketReader* r, EgoStateMessage* message);

void EncodeGlobalExtrinsic(const GlobalExtrinsicMessage& message, PacketWriter* w);
Status DecodeGlobalExtrinsic(int sender_id, PacketReader* r, GlobalExtrinsicMessage* message);

void EncodeTimeSync(const TimeSyncMessage& message, PacketWriter* w);
Status DecodeTimeSync(int sender_id, PacketReader* r, TimeSyncMessage* message);

void EncodeAirframe(const AirframeMessage& message, PacketWriter* w);
Status DecodeAirframe(int sender_id, PacketReader* r, AirframeMessage* message);

}  // namespace swarmlio::net::internal
