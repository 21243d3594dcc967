#include "swarmlio/net/message_channel.h"

#include <algorithm>
#include <string>

#include "swarmlio/net/wire_format.h"

namespace swarmlio::net {

MessageChannel::MessageChannel(const PacketCodec* codec, Transport* transport)
    : codec_(codec), transport_(transport), recent_(kMaxSwarmSize) {}

Status MessageChannel::Send(int64_t now_ns, int destination_id, const SwarmMessage& message,
                            int64_t local_now_ns) {
  if (SenderOf(message) != self_id()) {
    return Status::InvalidArgument("message sender " + std::to_string(SenderOf(message)) +
                                   " is not this endpoint's drone " + std::to_string(self_id()));
  }
  std::vector<uint8_t> packet;
  if (const auto* state = std::get_if<EgoStateMessage>(&message)) {
    EgoStateMessage stamped = *state;
    StampSendTime(local_now_ns, &stamped);
    SWARMLIO_RETURN_IF_ERROR(codec_->Encode(stamped, next_sequence_, &packet));
  } else {
    SWARMLIO_RETURN_IF_ERROR(codec_->Encode(message, next_sequence_, &packet));
  }
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

void MessageChannel::StampSendTime(int64_t now_ns, EgoStateMessage* m) {
  int64_t delay_ns = -1;
  if (__builtin_sub_overflow(now_ns, m->stamp_ns, &delay_ns) || delay_ns < 0 ||
      SyncDelayCode(delay_ns) > kSendDelayMaxCode) {
    delay_ns = -1;
  }
  m->send_delay_ns = delay_ns;
  if (delay_ns < 0) {
    // Echoes and the offset report are measured against the send delay:
    // without it they go, the state itself still leaves.
    ++stats_.send_delay_unknown;
    stats_.echoes_dropped += m->echoes.size();
    m->echoes.clear();
    m->offset_report.reset();
    return;
  }
  const size_t before = m->echoes.size();
  m->echoes.erase(std::remove_if(m->echoes.begin(), m->echoes.end(),
                                 [&](const StateEcho& e) {
                                   int64_t hold_ns = 0;
                                   return !StateEchoHoldNs(m->stamp_ns, delay_ns, e.arrival_ns,
                                                           &hold_ns) ||
                                          hold_ns < 0 || SyncDelayCode(hold_ns) > kHoldMaxCode;
                                 }),
                  m->echoes.end());
  stats_.echoes_dropped += before - m->echoes.size();
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
