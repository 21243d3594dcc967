// UdpTransport: net::Transport over IPv4 UDP with POSIX sockets, for drones
// in separate processes or on separate machines (docs/network.md, "UDP
// transport").
//
//   net::UdpOptions options;                     // multicast 239.255.88.21:8821
//   std::unique_ptr<net::UdpTransport> udp;
//   SWARMLIO_RETURN_IF_ERROR(net::UdpTransport::Create(options, self_id, &udp));
//   net::MessageChannel channel(&codec, udp.get());
//
// Modes: multicast (one datagram to a group every teammate joined) and
// broadcast (one datagram to a subnet broadcast address) reach all teammates
// with one send, whatever the destination id: receivers filter on the
// authenticated content. Unicast sends to the addresses of a static peer
// table, one copy per peer for kBroadcastId (for networks without multicast,
// or several processes on one machine when multicast is not available).
//
// The transport moves bytes and never interprets them: decoding and
// authentication are the PacketCodec's (MessageChannel). Datagram::source_id
// is looked up from the source address in the peer table (-1 if absent) and
// is not authenticated. A datagram's arrival time is the `now_ns` given to
// Poll. Own packets that multicast/broadcast loop back are returned like any
// other (MessageChannel drops them). Errors are Status values with the errno
// text; nothing is printed. One thread uses a UdpTransport at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/net/transport.h"

namespace swarmlio::net {

enum class UdpMode { kMulticast, kBroadcast, kUnicast };

}  // namespace swarmlio::net

namespace swarmlio::config {
template <>
struct EnumTraits<net::UdpMode> {
  static constexpr std::array<std::pair<net::UdpMode, const char*>, 3> kNames{{
      {net::UdpMode::kMulticast, "multicast"},
      {net::UdpMode::kBroadcast, "broadcast"},
      {net::UdpMode::kUnicast, "unicast"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::net {

/// One teammate's address (unicast mode; in the other modes only used to
/// fill Datagram::source_id).
struct UdpPeer {
  int id = 0;
  std::string address = "127.0.0.1";  // IPv4, dotted quad
  int port = 8821;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("id", id, FieldSpec::InRange(0, kMaxSwarmSize - 1, "", "drone id"));
    v("address", address, FieldSpec::Doc("IPv4 address of the drone"));
    v("port", port, FieldSpec::InRange(1, 65535, "", "UDP port the drone listens on"));
  }
  std::string Validate() const;
};

/// YAML section `udp`.
struct UdpOptions {
  UdpMode mode = UdpMode::kMulticast;
  int port = 8821;                                    // multicast/broadcast: shared by the swarm;
                                                      // unicast: this drone's port
  std::string multicast_group = "239.255.88.21";      // administratively scoped 239/8
  std::string interface_address = "0.0.0.0";          // multicast: interface to join and send
                                                      // on (0.0.0.0: the routing table's choice);
                                                      // unicast: address to bind
  std::string broadcast_address = "255.255.255.255";  // broadcast mode destination
  int multicast_ttl = 1;                              // hops; 0 keeps packets on this machine
  bool multicast_loopback = true;     // deliver to the other processes on this machine
  int receive_buffer_bytes = 0;       // SO_RCVBUF, 0: system default
  int send_buffer_bytes = 0;          // SO_SNDBUF, 0: system default
  int max_datagrams_per_poll = 4096;  // bounds one Poll under a flood
  std::vector<UdpPeer> peers;         // unicast: every teammate (self is skipped)

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("mode", mode, FieldSpec::Doc("multicast, broadcast or unicast (to the peers)"));
    v("port", port, FieldSpec::InRange(1, 65535, "", "UDP port"));
    v("multicast_group", multicast_group, FieldSpec::Doc("IPv4 multicast group (224/4)"));
    v("interface_address", interface_address,
      FieldSpec::Doc("multicast interface / unicast bind address (IPv4)"));
    v("broadcast_address", broadcast_address, FieldSpec::Doc("broadcast destination (IPv4)"));
    v("multicast_ttl", multicast_ttl, FieldSpec::InRange(0, 255, "", "multicast hop limit"));
    v("multicast_loopback", multicast_loopback,
      FieldSpec::Doc("deliver multicast to other sockets on this machine"));
    v("receive_buffer_bytes", receive_buffer_bytes,
      FieldSpec::InRange(0, 1 << 28, "B", "SO_RCVBUF, 0 for the system default"));
    v("send_buffer_bytes", send_buffer_bytes,
      FieldSpec::InRange(0, 1 << 28, "B", "SO_SNDBUF, 0 for the system default"));
    v("max_datagrams_per_poll", max_datagrams_per_poll,
      FieldSpec::InRange(1, 1 << 20, "", "datagrams read by one Poll at most"));
    v("peers", peers);
  }
  /// Ranges, parseable addresses, a multicast group in 224/4, distinct peer ids.
  std::string Validate() const;
};

/// Socket counters. Wire bytes add the IPv4 (20 B) and UDP (8 B) headers of
/// every datagram, so wire_bytes / elapsed time is the bandwidth on the link
/// (without the link layer's own framing).
struct UdpStats {
  static constexpr uint64_t kHeaderBytes = 28;

  uint64_t datagrams_sent = 0;      // accepted by the kernel (one per copy)
  uint64_t bytes_sent = 0;          // payload bytes
  uint64_t wire_bytes_sent = 0;     // payload + 28 per datagram
  uint64_t send_dropped = 0;        // socket buffer full (EAGAIN, ENOBUFS): lost
  uint64_t send_rejected = 0;       // empty or > kMaxPacketBytes: never sent
  uint64_t datagrams_received = 0;  // read from the socket (including dropped ones)
  uint64_t bytes_received = 0;
  uint64_t wire_bytes_received = 0;
  uint64_t dropped_oversized = 0;  // > kMaxPacketBytes
  uint64_t dropped_empty = 0;      // zero-length
};

class UdpTransport : public Transport {
 public:
  /// Opens and configures the socket. InvalidArgument for bad options or id,
  /// IoError (with errno text) when a socket call fails.
  static Status Create(const UdpOptions& options,
                       int self_id,
                       std::unique_ptr<UdpTransport>* transport);
  ~UdpTransport() override;
  UdpTransport(const UdpTransport&) = delete;
  UdpTransport& operator=(const UdpTransport&) = delete;

  int self_id() const override { return self_id_; }
  /// See Transport::Send. Multicast/broadcast: one datagram for any
  /// destination. Unicast: to the peer (NotFound if not in the table), one
  /// copy per peer for kBroadcastId. A full socket buffer drops the datagram
  /// (counted, Ok); other socket errors are IoError.
  Status Send(int64_t now_ns, int destination_id, const uint8_t* data, size_t size) override;
  /// Reads every datagram waiting on the socket (up to max_datagrams_per_poll)
  /// with arrival_ns = now_ns. Oversized and empty ones are counted and dropped.
  Status Poll(int64_t now_ns, std::vector<Datagram>* received) override;

  const UdpStats& stats() const { return stats_; }
  /// The port the socket is bound to.
  int local_port() const { return local_port_; }

 private:
  struct PeerAddress;
  UdpTransport(const UdpOptions& options, int self_id);
  Status SendTo(const void* address, const uint8_t* data, size_t size);

  UdpOptions options_;
  int self_id_;
  int fd_ = -1;
  int local_port_ = 0;
  std::vector<PeerAddress> peers_;
  std::unique_ptr<PeerAddress> group_;  // multicast group or broadcast address
  std::vector<uint8_t> buffer_;         // kMaxPacketBytes + 1
  UdpStats stats_;
};

}  // namespace swarmlio::net
