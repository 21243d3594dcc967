// UdpTransport on the loopback interface: several transports in this process
// (different drone ids, same multicast group and port) exchange datagrams;
// unicast and broadcast modes; size limits on send and receive; counters;
// socket errors as Status. Every socket binds to or sends on 127.0.0.1 only.
#include "swarmlio/net/udp_transport.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/net/message_channel.h"
#include "tests/net/net_test_util.h"
#include "test_utils/free_port.h"

namespace swarmlio::net {
namespace {

/// A UDP socket closed on scope exit.
class Socket {
 public:
  Socket() : fd_(socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {}
  ~Socket() {
    if (fd_ >= 0) close(fd_);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

sockaddr_in Address(const std::string& ip, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, ip.c_str(), &a.sin_addr);
  return a;
}

std::string Errno(const std::string& call) {
  return call + ": " + std::generic_category().message(errno);
}

/// A multicast group of 239.255/16 picked from the process id.
std::string TestGroup() {
  const unsigned pid = static_cast<unsigned>(getpid());
  return "239.255." + std::to_string((pid >> 8) % 256) + "." + std::to_string(pid % 254 + 1);
}

/// Whether this machine delivers IPv4 multicast over loopback, checked with
/// plain sockets (independently of the code under test). Empty if it does,
/// otherwise the reason.
std::string MulticastUnavailableReason(const std::string& group, int port) {
  Socket receiver, sender;
  const int one = 1;
  setsockopt(receiver.fd(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  setsockopt(receiver.fd(), SOL_SOCKET, SO_REUSEPORT, &one, sizeof(one));
  sockaddr_in bind_address = Address(group, port);
  if (bind(receiver.fd(), reinterpret_cast<sockaddr*>(&bind_address), sizeof(bind_address)) != 0) {
    return Errno("bind " + group);
  }
  ip_mreq membership{};
  inet_pton(AF_INET, group.c_str(), &membership.imr_multiaddr);
  inet_pton(AF_INET, "127.0.0.1", &membership.imr_interface);
  if (setsockopt(receiver.fd(), IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof(membership)) !=
      0) {
    return Errno("IP_ADD_MEMBERSHIP on 127.0.0.1");
  }
  in_addr multicast_interface{};
  inet_pton(AF_INET, "127.0.0.1", &multicast_interface);
  if (setsockopt(sender.fd(), IPPROTO_IP, IP_MULTICAST_IF, &multicast_interface,
                 sizeof(multicast_interface)) != 0) {
    return Errno("IP_MULTICAST_IF 127.0.0.1");
  }
  const sockaddr_in destination = Address(group, port);
  const char probe[] = "probe";
  if (sendto(sender.fd(), probe, sizeof(probe), 0, reinterpret_cast<const sockaddr*>(&destination),
             sizeof(destination)) < 0) {
    return Errno("sendto " + group);
  }
  pollfd p{receiver.fd(), POLLIN, 0};
  if (poll(&p, 1, 1000) != 1) return "a multicast datagram sent on 127.0.0.1 did not arrive in 1 s";
  return "";
}

UdpOptions MulticastOptions(int port) {
  UdpOptions o;
  o.mode = UdpMode::kMulticast;
  o.multicast_group = TestGroup();
  o.port = port;
  o.interface_address = "127.0.0.1";
  o.multicast_ttl = 0;  // never leaves this machine
  return o;
}

/// Polls until `count` datagrams arrived in total or `timeout_ms` passed;
/// `now_ns` advances by 1 ms per poll.
std::vector<Datagram> PollFor(UdpTransport* transport,
                              size_t count,
                              int64_t* now_ns,
                              int timeout_ms = 2000) {
  std::vector<Datagram> received;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (received.size() < count && std::chrono::steady_clock::now() < deadline) {
    *now_ns += 1'000'000;
    const Status s = transport->Poll(*now_ns, &received);
    EXPECT_TRUE(s.ok()) << s.message();
    if (received.size() < count) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Anything beyond `count` that is already queued shows up here too.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(transport->Poll(*now_ns, &received).ok());
  return received;
}

std::vector<uint8_t> Payload(uint8_t tag, size_t size) {
  std::vector<uint8_t> bytes(size);
  for (size_t i = 0; i < size; ++i) bytes[i] = static_cast<uint8_t>(tag + i);
  return bytes;
}

// ---------------------------------------------------------------------------

TEST(UdpOptions, ValidateNamesTheKey) {
  EXPECT_EQ(UdpOptions().Validate(), "");
  UdpOptions o;
  o.multicast_group = "10.0.0.1";
  EXPECT_NE(o.Validate().find("multicast_group"), std::string::npos) << o.Validate();
  o = UdpOptions();
  o.interface_address = "localhost";
  EXPECT_NE(o.Validate().find("interface_address"), std::string::npos) << o.Validate();
  o = UdpOptions();
  o.port = 70000;
  EXPECT_NE(o.Validate().find("port"), std::string::npos) << o.Validate();
  o = UdpOptions();
  o.mode = UdpMode::kUnicast;
  EXPECT_NE(o.Validate().find("peers"), std::string::npos) << o.Validate();
  o.peers = {UdpPeer{1, "127.0.0.1", 9000}, UdpPeer{1, "127.0.0.1", 9001}};
  EXPECT_NE(o.Validate().find("peers[1].id"), std::string::npos) << o.Validate();
  o.peers = {UdpPeer{1, "127.0.0.300", 9000}};
  EXPECT_NE(o.Validate().find("peers[0].address"), std::string::npos) << o.Validate();

  std::unique_ptr<UdpTransport> t;
  Status s = UdpTransport::Create(o, 1, &t);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("udp.peers[0].address"), std::string::npos) << s.message();
  s = UdpTransport::Create(UdpOptions(), 64, &t);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
}

TEST(UdpOptions, LoadFromYaml) {
  const std::string yaml =
      "udp:\n"
      "  mode: unicast\n"
      "  port: 9100\n"
      "  interface_address: 10.0.0.101\n"
      "  peers:\n"
      "    - {id: 1, address: 10.0.0.101, port: 9100}\n"
      "    - {id: 2, address: 10.0.0.102, port: 9100}\n"
      "bad:\n"
      "  mode: carrier_pigeon\n";
  config::ConfigFile file;
  ASSERT_TRUE(config::ConfigFile::Parse(yaml, "net.yaml", &file).ok());
  UdpOptions o;
  const Status s = file.Read("udp", &o);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(o.mode, UdpMode::kUnicast);
  EXPECT_EQ(o.port, 9100);
  ASSERT_EQ(o.peers.size(), 2u);
  EXPECT_EQ(o.peers[1].id, 2);
  EXPECT_EQ(o.peers[1].address, "10.0.0.102");
  UdpOptions bad;
  const Status e = file.Read("bad", &bad);
  EXPECT_FALSE(e.ok());
  EXPECT_NE(e.message().find("bad.mode"), std::string::npos) << e.message();
}

TEST(UdpTransport, ThreeDronesOnOneMulticastGroupSeeEveryPacket) {
  const int port = swarmlio::testing::FreeLoopbackPort();
  ASSERT_GT(port, 0);
  const std::string reason = MulticastUnavailableReason(TestGroup(), port);
  if (!reason.empty()) {
    GTEST_SKIP() << "IPv4 multicast over loopback is not available here (" << reason
                 << "); the unicast mode is tested instead (UnicastPeersOnLoopback)";
  }
  std::vector<std::unique_ptr<UdpTransport>> drones(3);
  for (int id = 0; id < 3; ++id) {
    const Status s = UdpTransport::Create(MulticastOptions(port), id, &drones[id]);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(drones[id]->self_id(), id);
    EXPECT_EQ(drones[id]->local_port(), port);
  }
  // One send per drone reaches every drone, itself included (loopback): the
  // channel above drops its own packets.
  for (int id = 0; id < 3; ++id) {
    const std::vector<uint8_t> bytes = Payload(static_cast<uint8_t>(10 * id), 100 + id);
    ASSERT_TRUE(drones[id]->Send(0, kBroadcastId, bytes.data(), bytes.size()).ok());
  }
  int64_t now = 0;
  for (int id = 0; id < 3; ++id) {
    const std::vector<Datagram> received = PollFor(drones[id].get(), 3, &now);
    ASSERT_EQ(received.size(), 3u) << "drone " << id;
    std::vector<bool> seen(3, false);
    for (const Datagram& d : received) {
      const int sender = static_cast<int>(d.bytes.size()) - 100;
      ASSERT_GE(sender, 0);
      ASSERT_LT(sender, 3);
      EXPECT_EQ(d.bytes, Payload(static_cast<uint8_t>(10 * sender), 100 + sender));
      EXPECT_EQ(d.source_id, -1);  // no peer table
      EXPECT_GT(d.arrival_ns, 0);
      EXPECT_LE(d.arrival_ns, now);
      seen[sender] = true;
    }
    EXPECT_EQ(seen, std::vector<bool>(3, true));
    const UdpStats& stats = drones[id]->stats();
    EXPECT_EQ(stats.datagrams_sent, 1u);
    EXPECT_EQ(stats.bytes_sent, 100u + id);
    EXPECT_EQ(stats.wire_bytes_sent, 128u + id);
    EXPECT_EQ(stats.datagrams_received, 3u);
    EXPECT_EQ(stats.bytes_received, 303u);
    EXPECT_EQ(stats.wire_bytes_received, 303u + 3 * UdpStats::kHeaderBytes);
  }
  // A packet for one drone is still one datagram to the group.
  const std::vector<uint8_t> bytes = Payload(7, 50);
  ASSERT_TRUE(drones[0]->Send(0, 2, bytes.data(), bytes.size()).ok());
  EXPECT_EQ(PollFor(drones[1].get(), 1, &now).size(), 1u);
  EXPECT_EQ(PollFor(drones[2].get(), 1, &now).size(), 1u);
}

TEST(UdpTransport, MessageChannelsOverMulticast) {
  const int port = swarmlio::testing::FreeLoopbackPort();
  const std::string reason = MulticastUnavailableReason(TestGroup(), port);
  if (!reason.empty()) {
    GTEST_SKIP() << "IPv4 multicast over loopback is not available here (" << reason << ")";
  }
  std::unique_ptr<UdpTransport> udp0, udp1, udp2;
  ASSERT_TRUE(UdpTransport::Create(MulticastOptions(port), 0, &udp0).ok());
  ASSERT_TRUE(UdpTransport::Create(MulticastOptions(port), 1, &udp1).ok());
  ASSERT_TRUE(UdpTransport::Create(MulticastOptions(port), 2, &udp2).ok());
  const PacketCodec swarm = net_test::MakeCodec(1);
  const PacketCodec intruder = net_test::MakeCodec(2);
  MessageChannel c0(&swarm, udp0.get());
  MessageChannel c1(&swarm, udp1.get());
  MessageChannel hostile(&intruder, udp2.get());
  const EgoStateMessage ego = net_test::MakeEgoState(0, 3, 5);
  ASSERT_TRUE(c0.Send(1000, kBroadcastId, ego).ok());
  ASSERT_TRUE(hostile.Send(1000, kBroadcastId, net_test::MakeEgoState(2, 0, 6)).ok());

  std::vector<ReceivedMessage> inbox;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  int64_t now = 2000;
  while (c1.stats().received + c1.stats().rejected < 2 &&
         std::chrono::steady_clock::now() < deadline) {
    ASSERT_TRUE(c1.Poll(++now, &inbox).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(inbox.size(), 1u);
  EXPECT_EQ(inbox[0].header.sender_id, 0);
  EXPECT_EQ(inbox[0].arrival_ns, now);
  net_test::ExpectSameMessage(ego, inbox[0].message);
  EXPECT_EQ(c1.stats().rejected, 1u);  // the foreign key
  // The sender hears its own packet back and drops it.
  std::vector<ReceivedMessage> own;
  for (int k = 0; k < 200 && c0.stats().own_packets == 0; ++k) {
    ASSERT_TRUE(c0.Poll(++now, &own).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(c0.stats().own_packets, 1u);
}

TEST(UdpTransport, RejectsEmptyAndOversizedPacketsOnSend) {
  const int port = swarmlio::testing::FreeLoopbackPort();
  UdpOptions o;
  o.mode = UdpMode::kUnicast;
  o.interface_address = "127.0.0.1";
  o.port = port;
  o.peers = {UdpPeer{0, "127.0.0.1", port}, UdpPeer{1, "127.0.0.1", swarmlio::testing::FreeLoopbackPort()}};
  std::unique_ptr<UdpTransport> t;
  ASSERT_TRUE(UdpTransport::Create(o, 0, &t).ok());
  const std::vector<uint8_t> big(kMaxPacketBytes + 1, 1);
  EXPECT_EQ(t->Send(0, 1, big.data(), big.size()).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(t->Send(0, 1, big.data(), 0).code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(t->Send(0, 1, big.data(), kMaxPacketBytes).ok());  // the largest allowed
  EXPECT_EQ(t->stats().send_rejected, 2u);
  EXPECT_EQ(t->stats().datagrams_sent, 1u);
  EXPECT_EQ(t->stats().wire_bytes_sent, kMaxPacketBytes + UdpStats::kHeaderBytes);
  // Addressing errors.
  EXPECT_EQ(t->Send(0, 0, big.data(), 10).code(), Status::Code::kInvalidArgument);  // self
  EXPECT_EQ(t->Send(0, 64, big.data(), 10).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(t->Send(0, 5, big.data(), 10).code(), Status::Code::kNotFound);
}

TEST(UdpTransport, DropsEmptyAndOversizedDatagramsOnReceive) {
  const int port = swarmlio::testing::FreeLoopbackPort();
  UdpOptions o;
  o.mode = UdpMode::kUnicast;
  o.interface_address = "127.0.0.1";
  o.port = port;
  o.peers = {UdpPeer{1, "127.0.0.1", 1}};
  std::unique_ptr<UdpTransport> t;
  ASSERT_TRUE(UdpTransport::Create(o, 0, &t).ok());
  // Raw datagrams from outside the swarm: the receive side must not trust sizes.
  Socket raw;
  const sockaddr_in to = Address("127.0.0.1", port);
  for (size_t size : {size_t{0}, kMaxPacketBytes + 1, size_t{9000}, size_t{40}, kMaxPacketBytes}) {
    const std::vector<uint8_t> bytes(size, 0xAB);
    ASSERT_EQ(
        sendto(raw.fd(), bytes.data(), size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to)),
        static_cast<ssize_t>(size))
        << Errno("sendto");
  }
  int64_t now = 0;
  const std::vector<Datagram> received = PollFor(t.get(), 2, &now);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received[0].bytes.size(), 40u);
  EXPECT_EQ(received[1].bytes.size(), kMaxPacketBytes);
  EXPECT_EQ(received[0].source_id, -1);  // not in the peer table
  const UdpStats& s = t->stats();
  EXPECT_EQ(s.datagrams_received, 5u);
  EXPECT_EQ(s.dropped_empty, 1u);
  EXPECT_EQ(s.dropped_oversized, 2u);
  // The real lengths count on the wire, the oversized ones included.
  EXPECT_EQ(s.bytes_received, 0 + 1201 + 9000 + 40 + 1200u);
  EXPECT_EQ(s.wire_bytes_received, s.bytes_received + 5 * UdpStats::kHeaderBytes);
}

TEST(UdpTransport, UnicastPeersOnLoopback) {
  // The fallback where multicast is not available: one port per drone on
  // 127.0.0.1 and a static peer table.
  const std::vector<int> ports = {swarmlio::testing::FreeLoopbackPort(), swarmlio::testing::FreeLoopbackPort(), swarmlio::testing::FreeLoopbackPort()};
  std::vector<std::unique_ptr<UdpTransport>> drones(3);
  for (int id = 0; id < 3; ++id) {
    UdpOptions o;
    o.mode = UdpMode::kUnicast;
    o.interface_address = "127.0.0.1";
    o.port = ports[id];
    for (int peer = 0; peer < 3; ++peer) o.peers.push_back({peer, "127.0.0.1", ports[peer]});
    const Status s = UdpTransport::Create(o, id, &drones[id]);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  const std::vector<uint8_t> hello = Payload(1, 64);
  ASSERT_TRUE(drones[0]->Send(0, kBroadcastId, hello.data(), hello.size()).ok());
  EXPECT_EQ(drones[0]->stats().datagrams_sent, 2u);  // one copy per teammate
  EXPECT_EQ(drones[0]->stats().wire_bytes_sent, 2 * (64 + UdpStats::kHeaderBytes));
  const std::vector<uint8_t> direct = Payload(2, 32);
  ASSERT_TRUE(drones[2]->Send(0, 1, direct.data(), direct.size()).ok());
  int64_t now = 0;
  const std::vector<Datagram> at1 = PollFor(drones[1].get(), 2, &now);
  ASSERT_EQ(at1.size(), 2u);
  for (const Datagram& d : at1) {
    EXPECT_EQ(d.source_id, d.bytes.size() == 64 ? 0 : 2);  // from the peer table
    EXPECT_EQ(d.bytes, d.bytes.size() == 64 ? hello : direct);
  }
  const std::vector<Datagram> at2 = PollFor(drones[2].get(), 1, &now);
  ASSERT_EQ(at2.size(), 1u);
  EXPECT_EQ(at2[0].bytes, hello);
  EXPECT_TRUE(PollFor(drones[0].get(), 1, &now, 50).empty());  // no echo in unicast
}

TEST(UdpTransport, PollDrainsTheSocketInBoundedSteps) {
  const int port = swarmlio::testing::FreeLoopbackPort();
  UdpOptions o;
  o.mode = UdpMode::kUnicast;
  o.interface_address = "127.0.0.1";
  o.port = port;
  o.peers = {UdpPeer{0, "127.0.0.1", port}, UdpPeer{1, "127.0.0.1", swarmlio::testing::FreeLoopbackPort()}};
  o.max_datagrams_per_poll = 40;
  std::unique_ptr<UdpTransport> receiver, sender;
  ASSERT_TRUE(UdpTransport::Create(o, 0, &receiver).ok());
  UdpOptions so = o;
  so.port = o.peers[1].port;
  ASSERT_TRUE(UdpTransport::Create(so, 1, &sender).ok());
  for (int k = 0; k < 100; ++k) {
    const std::vector<uint8_t> bytes = Payload(static_cast<uint8_t>(k), 20);
    ASSERT_TRUE(sender->Send(k, 0, bytes.data(), bytes.size()).ok());
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::vector<Datagram> received;
  ASSERT_TRUE(receiver->Poll(1, &received).ok());
  EXPECT_EQ(received.size(), 40u);
  ASSERT_TRUE(receiver->Poll(2, &received).ok());
  ASSERT_TRUE(receiver->Poll(3, &received).ok());
  ASSERT_EQ(received.size(), 100u);
  for (int k = 0; k < 100; ++k) {  // in order on loopback
    EXPECT_EQ(received[k].bytes, Payload(static_cast<uint8_t>(k), 20));
    EXPECT_EQ(received[k].arrival_ns, k < 40 ? 1 : (k < 80 ? 2 : 3));
  }
  ASSERT_TRUE(receiver->Poll(4, &received).ok());
  EXPECT_EQ(received.size(), 100u);
}

TEST(UdpTransport, BroadcastOnLoopback) {
  const int port = swarmlio::testing::FreeLoopbackPort();
  UdpOptions o;
  o.mode = UdpMode::kBroadcast;
  o.broadcast_address = "127.255.255.255";
  o.port = port;
  std::unique_ptr<UdpTransport> a, b;
  ASSERT_TRUE(UdpTransport::Create(o, 0, &a).ok());
  ASSERT_TRUE(UdpTransport::Create(o, 1, &b).ok());
  const std::vector<uint8_t> bytes = Payload(3, 77);
  const Status sent = a->Send(0, kBroadcastId, bytes.data(), bytes.size());
  if (sent.code() == Status::Code::kIoError) {
    GTEST_SKIP() << "broadcast to 127.255.255.255 is not permitted here: " << sent.message();
  }
  ASSERT_TRUE(sent.ok()) << sent.message();
  int64_t now = 0;
  const std::vector<Datagram> at_b = PollFor(b.get(), 1, &now);
  ASSERT_EQ(at_b.size(), 1u);
  EXPECT_EQ(at_b[0].bytes, bytes);
  EXPECT_EQ(PollFor(a.get(), 1, &now).size(), 1u);  // broadcast loops back to the sender too
}

TEST(UdpTransport, BandwidthFromTheSocketCounters) {
  // One second of a drone with two teammates at 10 Hz: 10 EgoStates with 2
  // observations, one GlobalExtrinsic with 4 entries, and the clock sync at
  // 1 Hz (a request to and a response for each teammate). Each send is one
  // datagram, as in multicast mode; the counters include the IPv4 + UDP headers.
  const int port = swarmlio::testing::FreeLoopbackPort();
  UdpOptions o;
  o.mode = UdpMode::kUnicast;
  o.interface_address = "127.0.0.1";
  o.port = port;
  o.peers = {UdpPeer{1, "127.0.0.1", swarmlio::testing::FreeLoopbackPort()}};
  std::unique_ptr<UdpTransport> udp;
  ASSERT_TRUE(UdpTransport::Create(o, 0, &udp).ok());
  const PacketCodec codec = net_test::MakeCodec();
  MessageChannel channel(&codec, udp.get());
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(channel.Send(k, 1, net_test::MakeEgoState(0, 2, k)).ok());
  }
  ASSERT_TRUE(channel.Send(10, 1, net_test::MakeGlobalExtrinsic(0, 4, 1)).ok());
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(channel.Send(11, 1, net_test::MakeTimeSync(0, 1, false)).ok());
    ASSERT_TRUE(channel.Send(12, 1, net_test::MakeTimeSync(0, 1, true)).ok());
  }
  const uint64_t expected_payload =
      10 * EgoStatePacketBytes(2) + GlobalExtrinsicPacketBytes(4) + 4 * TimeSyncPacketBytes();
  const UdpStats& s = udp->stats();
  EXPECT_EQ(s.datagrams_sent, 15u);
  EXPECT_EQ(s.bytes_sent, expected_payload);
  EXPECT_EQ(s.wire_bytes_sent, expected_payload + 15 * UdpStats::kHeaderBytes);
  std::printf(
      "[ figures  ] one drone, 2 teammates, 10 Hz: %llu B/s on the wire "
      "(EgoState k=2 %zu B + 28, GlobalExtrinsic n=4 %zu B + 28, TimeSync %zu B + 28)\n",
      static_cast<unsigned long long>(s.wire_bytes_sent), EgoStatePacketBytes(2),
      GlobalExtrinsicPacketBytes(4), TimeSyncPacketBytes());
}

TEST(UdpTransport, SocketErrorsAreStatusesWithTheErrnoText) {
  UdpOptions o;
  o.mode = UdpMode::kUnicast;
  o.interface_address = "203.0.113.7";  // TEST-NET-3: not an address of this machine
  o.port = swarmlio::testing::FreeLoopbackPort();
  o.peers = {UdpPeer{1, "127.0.0.1", 9}};
  std::unique_ptr<UdpTransport> t;
  const Status s = UdpTransport::Create(o, 0, &t);
  ASSERT_EQ(s.code(), Status::Code::kIoError);
  EXPECT_NE(s.message().find("bind 203.0.113.7"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find(std::generic_category().message(EADDRNOTAVAIL)), std::string::npos)
      << s.message();
  EXPECT_EQ(t, nullptr);
}

}  // namespace
}  // namespace swarmlio::net
