// The packet-decoder fuzz target's input layout, shared by the target and its
// seed generator (docs/network.md, "Fuzzing and sanitizers in CI").
//
//   byte 0 bit 0 = 0  raw mode: bytes [1, n) are the packet, decoded as they
//                     are (almost every mutation dies at the tag check);
//   byte 0 bit 0 = 1  signed mode: bytes [1, n) are a packet without its tag
//                     (header + payload); the target appends the correct tag
//                     under the fuzz key, so mutations of the header and the
//                     payload reach the checks behind the tag.
//
// The tag is the first kTagBytes bytes of HMAC-SHA512-256 over every byte
// before it, so nothing here depends on the header or payload layout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/swarm_key.h"

namespace swarmlio::fuzz {

enum class InputMode : uint8_t { kRawPacket = 0, kSignedPacket = 1 };

/// The fixed key of the fuzz target (never a real swarm's).
const net::SwarmKey& FuzzKey();

/// A codec under FuzzKey(), created once.
const net::PacketCodec& FuzzCodec();

/// `size` bytes (header + payload) followed by their tag under FuzzKey().
std::vector<uint8_t> AppendTag(const uint8_t* data, size_t size);

/// The packet the target decodes for a fuzzer input (see the layout above);
/// false for an empty input.
bool PacketFromInput(const uint8_t* data, size_t size, std::vector<uint8_t>* packet);

/// The fuzzer input in `mode` that reproduces `packet` (an encoded packet).
std::vector<uint8_t> InputFromPacket(InputMode mode, const std::vector<uint8_t>& packet);

}  // namespace swarmlio::fuzz
