// SwarmKey: the pre-shared 256-bit key that authenticates every swarm packet
// (HMAC-SHA512-256, libsodium crypto_auth). See docs/network.md, "Security".
//
// Every drone of one swarm holds the same key, so the tag proves "sent by a
// swarm member and unmodified", not which member: a compromised drone can
// impersonate the others. The key is wiped from memory on destruction.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "swarmlio/common/status.h"

namespace swarmlio::net {

class SwarmKey {
 public:
  static constexpr size_t kBytes = 32;  // crypto_auth_KEYBYTES

  /// All-zero key: usable, but only for tests and simulation.
  SwarmKey() = default;
  SwarmKey(const SwarmKey& other) = default;
  SwarmKey& operator=(const SwarmKey& other) = default;
  ~SwarmKey();

  /// Exactly kBytes bytes, else InvalidArgument.
  static Status FromBytes(const uint8_t* data, size_t size, SwarmKey* key);
  /// 64 hex digits (case-insensitive, surrounding whitespace ignored), as
  /// written by `head -c 32 /dev/urandom | xxd -p -c 64`.
  static Status FromHex(const std::string& hex, SwarmKey* key);
  /// A deterministic key for simulation and tests: bytes derived from `seed`.
  /// Never use on real drones.
  static SwarmKey ForSimulation(uint64_t seed);

  const uint8_t* data() const { return bytes_.data(); }

 private:
  std::array<uint8_t, kBytes> bytes_{};
};

}  // namespace swarmlio::net
