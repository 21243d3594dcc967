#include "swarmlio/net/swarm_key.h"

#include <sodium.h>

#include <algorithm>
#include <cctype>

#include "src/net/random.h"

namespace swarmlio::net {

static_assert(SwarmKey::kBytes == crypto_auth_KEYBYTES, "crypto_auth key size");

SwarmKey::~SwarmKey() { sodium_memzero(bytes_.data(), bytes_.size()); }

Status SwarmKey::FromBytes(const uint8_t* data, size_t size, SwarmKey* key) {
  if (size != kBytes) {
    return Status::InvalidArgument("swarm key must be " + std::to_string(kBytes) + " bytes, got " +
                                   std::to_string(size));
  }
  std::copy(data, data + size, key->bytes_.begin());
  return Status::Ok();
}

Status SwarmKey::FromHex(const std::string& hex, SwarmKey* key) {
  size_t begin = 0;
  size_t end = hex.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(hex[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(hex[end - 1]))) --end;
  if (end - begin != 2 * kBytes) {
    return Status::InvalidArgument("swarm key must be " + std::to_string(2 * kBytes) +
                                   " hex digits, got " + std::to_string(end - begin));
  }
  auto nibble = [](char ch) -> int {
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
  };
  SwarmKey parsed;
  for (size_t i = 0; i < kBytes; ++i) {
    const int hi = nibble(hex[begin + 2 * i]);
    const int lo = nibble(hex[begin + 2 * i + 1]);
    if (hi < 0 || lo < 0) {
      return Status::InvalidArgument("swarm key: non-hex character near digit " +
                                     std::to_string(2 * i));
    }
    parsed.bytes_[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  *key = parsed;
  return Status::Ok();
}

SwarmKey SwarmKey::ForSimulation(uint64_t seed) {
  SwarmKey key;
  uint64_t state = seed ^ 0x5357'41524d4b4559ull;  // "SWARMKEY"
  for (size_t i = 0; i < kBytes; i += 8) {
    const uint64_t word = internal::SplitMix64(&state);
    for (size_t b = 0; b < 8; ++b) key.bytes_[i + b] = static_cast<uint8_t>(word >> (8 * b));
  }
  return key;
}

}  // namespace swarmlio::net
