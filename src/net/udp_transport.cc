// UdpTransport: non-blocking IPv4 UDP socket (multicast, broadcast or
// unicast to a peer table). See the header and docs/network.md.
#include "swarmlio/net/udp_transport.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <set>
#include <system_error>

#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {
namespace {

std::string ErrnoText(int error) { return std::generic_category().message(error); }

Status SocketError(const std::string& call, int error) {
  return Status::IoError("udp: " + call + ": " + ErrnoText(error) + " (errno " +
                         std::to_string(error) + ")");
}

bool ParseIpv4(const std::string& text, in_addr* address) {
  return inet_pton(AF_INET, text.c_str(), address) == 1;
}

sockaddr_in MakeAddress(in_addr address, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr = address;
  a.sin_port = htons(static_cast<uint16_t>(port));
  return a;
}

std::string AddressText(const sockaddr_in& a) {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &a.sin_addr, text, sizeof(text));
  return std::string(text) + ":" + std::to_string(ntohs(a.sin_port));
}

template <class T>
Status SetOption(int fd, int level, int name, const T& value, const std::string& what) {
  if (setsockopt(fd, level, name, &value, sizeof(value)) != 0) {
    return SocketError("setsockopt(" + what + ")", errno);
  }
  return Status::Ok();
}

}  // namespace

struct UdpTransport::PeerAddress {
  int id = -1;
  sockaddr_in address{};
};

std::string UdpPeer::Validate() const {
  std::string error = config::ValidateFields(*this);
  in_addr parsed{};
  if (error.empty() && !ParseIpv4(address, &parsed)) {
    error = "address: '" + address + "' is not an IPv4 address";
  }
  return error;
}

std::string UdpOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  in_addr parsed{};
  if (!ParseIpv4(interface_address, &parsed)) {
    return "interface_address: '" + interface_address + "' is not an IPv4 address";
  }
  if (!ParseIpv4(broadcast_address, &parsed)) {
    return "broadcast_address: '" + broadcast_address + "' is not an IPv4 address";
  }
  if (!ParseIpv4(multicast_group, &parsed) || !IN_MULTICAST(ntohl(parsed.s_addr))) {
    return "multicast_group: '" + multicast_group + "' is not an IPv4 multicast address (224/4)";
  }
  std::set<int> ids;
  for (size_t i = 0; i < peers.size(); ++i) {
    if (!ids.insert(peers[i].id).second) {
      return config::IndexKey("peers", i) + ".id: " + std::to_string(peers[i].id) +
             " appears twice";
    }
  }
  if (mode == UdpMode::kUnicast && peers.empty()) return "peers: unicast mode needs the peer table";
  return "";
}

UdpTransport::UdpTransport(const UdpOptions& options, int self_id)
    : options_(options), self_id_(self_id), buffer_(kMaxPacketBytes + 1) {}

UdpTransport::~UdpTransport() {
  if (fd_ >= 0) close(fd_);
}

Status UdpTransport::Create(const UdpOptions& options,
                            int self_id,
                            std::unique_ptr<UdpTransport>* transport) {
  if (!IsValidDroneId(self_id)) {
    return Status::InvalidArgument("udp: drone id " + std::to_string(self_id) +
                                   " out of range 0.." + std::to_string(kMaxSwarmSize - 1));
  }
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument("udp." + error);

  std::unique_ptr<UdpTransport> t(new UdpTransport(options, self_id));
  for (const UdpPeer& p : options.peers) {
    PeerAddress peer;
    peer.id = p.id;
    in_addr a{};
    ParseIpv4(p.address, &a);
    peer.address = MakeAddress(a, p.port);
    t->peers_.push_back(peer);
  }
  in_addr interface_address{}, group{}, broadcast{};
  ParseIpv4(options.interface_address, &interface_address);
  ParseIpv4(options.multicast_group, &group);
  ParseIpv4(options.broadcast_address, &broadcast);

  t->fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (t->fd_ < 0) return SocketError("socket", errno);
  const int fd = t->fd_;
  const int one = 1;
  if (options.receive_buffer_bytes > 0) {
    SWARMLIO_RETURN_IF_ERROR(
        SetOption(fd, SOL_SOCKET, SO_RCVBUF, options.receive_buffer_bytes, "SO_RCVBUF"));
  }
  if (options.send_buffer_bytes > 0) {
    SWARMLIO_RETURN_IF_ERROR(
        SetOption(fd, SOL_SOCKET, SO_SNDBUF, options.send_buffer_bytes, "SO_SNDBUF"));
  }

  sockaddr_in bind_address{};
  switch (options.mode) {
    case UdpMode::kMulticast: {
      // Several processes on one machine share the port; each gets a copy.
      SWARMLIO_RETURN_IF_ERROR(SetOption(fd, SOL_SOCKET, SO_REUSEADDR, one, "SO_REUSEADDR"));
      SWARMLIO_RETURN_IF_ERROR(SetOption(fd, SOL_SOCKET, SO_REUSEPORT, one, "SO_REUSEPORT"));
      // Bound to the group: only datagrams sent to the group arrive.
      bind_address = MakeAddress(group, options.port);
      ip_mreq membership{};
      membership.imr_multiaddr = group;
      membership.imr_interface = interface_address;
      SWARMLIO_RETURN_IF_ERROR(SetOption(
          fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, membership,
          "IP_ADD_MEMBERSHIP " + options.multicast_group + " on " + options.interface_address));
      if (interface_address.s_addr != htonl(INADDR_ANY)) {
        SWARMLIO_RETURN_IF_ERROR(SetOption(fd, IPPROTO_IP, IP_MULTICAST_IF, interface_address,
                                           "IP_MULTICAST_IF " + options.interface_address));
      }
      const unsigned char ttl = static_cast<unsigned char>(options.multicast_ttl);
      const unsigned char loop = options.multicast_loopback ? 1 : 0;
      SWARMLIO_RETURN_IF_ERROR(
          SetOption(fd, IPPROTO_IP, IP_MULTICAST_TTL, ttl, "IP_MULTICAST_TTL"));
      SWARMLIO_RETURN_IF_ERROR(
          SetOption(fd, IPPROTO_IP, IP_MULTICAST_LOOP, loop, "IP_MULTICAST_LOOP"));
      t->group_ = std::make_unique<PeerAddress>();
      t->group_->address = MakeAddress(group, options.port);
      break;
    }
    case UdpMode::kBroadcast: {
      SWARMLIO_RETURN_IF_ERROR(SetOption(fd, SOL_SOCKET, SO_REUSEADDR, one, "SO_REUSEADDR"));
      SWARMLIO_RETURN_IF_ERROR(SetOption(fd, SOL_SOCKET, SO_REUSEPORT, one, "SO_REUSEPORT"));
      SWARMLIO_RETURN_IF_ERROR(SetOption(fd, SOL_SOCKET, SO_BROADCAST, one, "SO_BROADCAST"));
      in_addr any{};
      any.s_addr = htonl(INADDR_ANY);
      bind_address = MakeAddress(any, options.port);
      t->group_ = std::make_unique<PeerAddress>();
      t->group_->address = MakeAddress(broadcast, options.port);
      break;
    }
    case UdpMode::kUnicast:
      bind_address = MakeAddress(interface_address, options.port);
      break;
  }
  if (bind(fd, reinterpret_cast<const sockaddr*>(&bind_address), sizeof(bind_address)) != 0) {
    return SocketError("bind " + AddressText(bind_address), errno);
  }
  sockaddr_in local{};
  socklen_t length = sizeof(local);
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) != 0) {
    return SocketError("getsockname", errno);
  }
  t->local_port_ = ntohs(local.sin_port);
  *transport = std::move(t);
  return Status::Ok();
}

Status UdpTransport::SendTo(const void* address, const uint8_t* data, size_t size) {
  const auto* a = static_cast<const sockaddr_in*>(address);
  for (;;) {
    const ssize_t n =
        sendto(fd_, data, size, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(a), sizeof(*a));
    if (n >= 0) break;
    const int error = errno;
    if (error == EINTR) continue;
    if (error == EAGAIN || error == EWOULDBLOCK || error == ENOBUFS) {
      ++stats_.send_dropped;  // congestion: a lost datagram, not a failure
      return Status::Ok();
    }
    return SocketError("sendto " + AddressText(*a), error);
  }
  ++stats_.datagrams_sent;
  stats_.bytes_sent += size;
  stats_.wire_bytes_sent += size + UdpStats::kHeaderBytes;
  return Status::Ok();
}

Status UdpTransport::Send(int64_t /*now_ns*/,
                          int destination_id,
                          const uint8_t* data,
                          size_t size) {
  if (size == 0 || size > kMaxPacketBytes || data == nullptr) {
    ++stats_.send_rejected;
    return Status::InvalidArgument("udp: packet of " + std::to_string(size) + " B (must be 1.." +
                                   std::to_string(kMaxPacketBytes) + ")");
  }
  if (destination_id == self_id_ ||
      (destination_id != kBroadcastId && !IsValidDroneId(destination_id))) {
    return Status::InvalidArgument("udp: invalid destination " + std::to_string(destination_id));
  }
  if (options_.mode != UdpMode::kUnicast) return SendTo(&group_->address, data, size);

  Status first_error;
  bool found = false;
  for (const PeerAddress& peer : peers_) {
    if (peer.id == self_id_) continue;
    if (destination_id != kBroadcastId && peer.id != destination_id) continue;
    found = true;
    const Status s = SendTo(&peer.address, data, size);
    if (!s.ok() && first_error.ok()) first_error = s;
  }
  if (!found && destination_id != kBroadcastId) {
    return Status::NotFound("udp: drone " + std::to_string(destination_id) +
                            " is not in the peer table");
  }
  return first_error;
}

Status UdpTransport::Poll(int64_t now_ns, std::vector<Datagram>* received) {
  for (int count = 0; count < options_.max_datagrams_per_poll; ++count) {
    sockaddr_in source{};
    socklen_t source_length = sizeof(source);
    // MSG_TRUNC: the return value is the datagram's real length even when it
    // exceeds the buffer, so an oversized datagram is recognised.
    const ssize_t n = recvfrom(fd_, buffer_.data(), buffer_.size(), MSG_DONTWAIT | MSG_TRUNC,
                               reinterpret_cast<sockaddr*>(&source), &source_length);
    if (n < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      if (error == EAGAIN || error == EWOULDBLOCK) break;
      return SocketError("recvfrom", error);
    }
    const size_t length = static_cast<size_t>(n);
    ++stats_.datagrams_received;
    stats_.bytes_received += length;
    stats_.wire_bytes_received += length + UdpStats::kHeaderBytes;
    if (length == 0) {
      ++stats_.dropped_empty;
      continue;
    }
    if (length > kMaxPacketBytes) {
      ++stats_.dropped_oversized;
      continue;
    }
    Datagram d;
    d.arrival_ns = now_ns;
    int matches = 0;
    for (const PeerAddress& peer : peers_) {
      if (peer.address.sin_addr.s_addr == source.sin_addr.s_addr &&
          peer.address.sin_port == source.sin_port) {
        d.source_id = peer.id;
        ++matches;
      }
    }
    if (matches > 1) d.source_id = -1;  // several drones behind one address and port
    d.bytes.assign(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(length));
    received->push_back(std::move(d));
  }
  return Status::Ok();
}

}  // namespace swarmlio::net
