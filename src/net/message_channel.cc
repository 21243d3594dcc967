#include "swarmlio/net/message_channel.h"

#include <string>

namespace swarmlio::net {

MessageChannel::MessageChannel(const PacketCodec* codec, Transport* transport)
    : codec_(codec), transport_(transport), recent_(kMaxSwarmSize) {}

Status MessageChannel::Send(int64_t now_ns, int destination_id, const SwarmMessage& message) {
  if (SenderOf(message) != self_id()) {
    return Status::InvalidArgument("message sender " + std::to_string(SenderOf(message)) +
                                   " is not this endpoint's drone " + std::to_string(self_id()));
  }
  std::vector<uint8_t> packet;
  SWARMLIO_RETURN_IF_ERROR(codec_->Encode(message, next_sequence_, &packet));
  ++next_sequence_;
  SWARMLIO_RETURN_IF_ERROR(transport_->Send(now_ns, destination_id, packet.data(), packet.size()));
  ++stats_.sent;
  return Status::Ok();
}

Status MessageChannel::Poll(int64_t now_ns, std::vector<ReceivedMessage>* messages) {
  scratch_.clear();
  SWARMLIO_RETURN_IF_ERROR(transport_->Poll(now_ns, &scratch_));
  for (const Datagram& d : scratch_) {
    DecodedPacket decoded;
    const Status s = codec_->Decode(d.bytes.data(), d.bytes.size(), &decoded);
    if (!s.ok()) {
      ++stats_.rejected;
      stats_.last_reject_reason = s.message();
      continue;
    }
    if (decoded.header.sender_id == self_id()) {
      ++stats_.own_packets;
      continue;
    }
    if (IsDuplicate(decoded.header.sender_id, decoded.header.sequence)) {
      ++stats_.duplicates;
      continue;
    }
    ReceivedMessage m;
    m.arrival_ns = d.arrival_ns;
    m.header = decoded.header;
    m.message = std::move(decoded.message);
    messages->push_back(std::move(m));
    ++stats_.received;
  }
  return Status::Ok();
}

bool MessageChannel::IsDuplicate(int sender_id, uint32_t sequence) {
  RecentSequences& recent = recent_[sender_id];  // sender id was range-checked by Decode
  for (int i = 0; i < recent.count; ++i) {
    if (recent.ring[i] == sequence) return true;
  }
  recent.ring[recent.next] = sequence;
  recent.next = (recent.next + 1) % kDuplicateWindow;
  if (recent.count < kDuplicateWindow) ++recent.count;
  return false;
}

}  // namespace swarmlio::net
