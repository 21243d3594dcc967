// Fuzzer input <-> packet bytes for the packet-decoder fuzz target.
#include "tools/fuzz/fuzz_input.h"

#include <sodium.h>

#include <algorithm>
#include <cstdlib>

#include "swarmlio/net/wire_format.h"

namespace swarmlio::fuzz {

static_assert(net::kTagBytes <= crypto_auth_BYTES, "the tag is a prefix of HMAC-SHA512-256");

const net::SwarmKey& FuzzKey() {
  static const net::SwarmKey key = [] {
    if (sodium_init() < 0) std::abort();  // before the first crypto_auth
    return net::SwarmKey::ForSimulation(0x5F022);
  }();
  return key;
}

const net::PacketCodec& FuzzCodec() {
  static const net::PacketCodec codec = [] {
    net::PacketCodec c;
    if (!net::PacketCodec::Create(FuzzKey(), &c).ok()) std::abort();
    return c;
  }();
  return codec;
}

std::vector<uint8_t> AppendTag(const uint8_t* data, size_t size) {
  uint8_t mac[crypto_auth_BYTES];
  crypto_auth(mac, data, size, FuzzKey().data());
  std::vector<uint8_t> packet(data, data + size);
  packet.insert(packet.end(), mac, mac + net::kTagBytes);
  return packet;
}

bool PacketFromInput(const uint8_t* data, size_t size, std::vector<uint8_t>* packet) {
  if (size < 1) return false;
  if ((data[0] & 1) == static_cast<uint8_t>(InputMode::kRawPacket)) {
    packet->assign(data + 1, data + size);
  } else {
    *packet = AppendTag(data + 1, size - 1);
  }
  return true;
}

std::vector<uint8_t> InputFromPacket(InputMode mode, const std::vector<uint8_t>& packet) {
  std::vector<uint8_t> input{static_cast<uint8_t>(mode)};
  const size_t keep = mode == InputMode::kRawPacket
                          ? packet.size()
                          : packet.size() - std::min(packet.size(), net::kTagBytes);
  input.insert(input.end(), packet.begin(), packet.begin() + static_cast<std::ptrdiff_t>(keep));
  return input;
}

}  // namespace swarmlio::fuzz
