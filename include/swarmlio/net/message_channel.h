// MessageChannel: one drone's typed view of the swarm network, the layer the
// estimator talks to. It numbers outgoing packets, encodes them with the
// PacketCodec and sends them over any Transport; on Poll it decodes,
// authenticates and de-duplicates what arrived. Rejected packets are counted
// (with the last reason), not returned: a bad packet from the air is not an
// error of the caller.
//
//   net::MessageChannel channel(&codec, network->Endpoint(id));
//   SWARMLIO_RETURN_IF_ERROR(channel.Send(t_ns, net::kBroadcastId, ego_state));
//   std::vector<net::ReceivedMessage> inbox;
//   SWARMLIO_RETURN_IF_ERROR(channel.Poll(t_ns, &inbox));
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/transport.h"

namespace swarmlio::net {

struct ReceivedMessage {
  int64_t arrival_ns = 0;  // receiver's time line
  PacketHeader header;     // authenticated (sender id, sequence)
  SwarmMessage message;
};

struct ChannelStats {
  uint64_t sent = 0;         // packets handed to the transport
  uint64_t received = 0;     // messages returned by Poll
  uint64_t rejected = 0;     // failed decoding or authentication
  uint64_t duplicates = 0;   // same (sender, sequence) seen recently
  uint64_t own_packets = 0;  // our own packets echoed back (UDP broadcast)
  uint64_t send_delay_unknown = 0;  // EgoStates sent later than the wire's send delay range
  uint64_t echoes_dropped = 0;      // state echoes whose hold left the wire's range
  std::string last_reject_reason;
};

class MessageChannel {
 public:
  /// Packets from one sender whose sequence number is among the last
  /// kDuplicateWindow accepted from it are dropped as duplicates.
  static constexpr int kDuplicateWindow = 128;

  /// `codec` and `transport` must outlive the channel.
  MessageChannel(const PacketCodec* codec, Transport* transport);

  /// Encodes and sends; InvalidArgument if the message's sender is not this
  /// endpoint or the message breaks a codec rule; transport errors pass through.
  /// `now_ns` is the transport's time. An EgoState gets its send time here:
  /// send_delay_ns = local_now_ns - stamp_ns (the clock synchronisation's
  /// t1/t3, docs/network.md section 9), `local_now_ns` being the time the
  /// packet really leaves on the sender's clock (the clock of its stamps; the
  /// same as now_ns unless the transport runs on another time line, as the
  /// replay's true time does). When that delay, or an echo's hold, is outside
  /// the wire's range, the delay is sent as not known (and the echoes
  /// dropped) or the echo dropped, and counted.
  Status Send(int64_t now_ns, int destination_id, const SwarmMessage& message) {
    return Send(now_ns, destination_id, message, now_ns);
  }
  Status Send(int64_t now_ns, int destination_id, const SwarmMessage& message,
              int64_t local_now_ns);

  /// Appends the messages that arrived by `now_ns`, in arrival order.
  Status Poll(int64_t now_ns, std::vector<ReceivedMessage>* messages);

  const ChannelStats& stats() const { return stats_; }
  int self_id() const { return transport_->self_id(); }

 private:
  void StampSendTime(int64_t now_ns, EgoStateMessage* m);
  struct RecentSequences {
    std::array<uint32_t, kDuplicateWindow> ring{};
    int count = 0;
    int next = 0;
  };
  bool IsDuplicate(int sender_id, uint32_t sequence);

  const PacketCodec* codec_;
  Transport* transport_;
  uint32_t next_sequence_ = 0;
  std::vector<RecentSequences> recent_;  // indexed by sender id
  std::vector<Datagram> scratch_;
  ChannelStats stats_;
};

}  // namespace swarmlio::net
