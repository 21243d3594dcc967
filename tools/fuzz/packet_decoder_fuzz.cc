// libFuzzer target for net::PacketCodec::Decode (docs/network.md, "Fuzzing
// and sanitizers in CI"). Input layout: fuzz_input.h (raw packets, or packets
// the target signs so that the checks behind the tag are reached).
//
// A bug is any crash or sanitizer report, and any packet Decode accepts whose
// message fails CheckMessage, disagrees with the header (sender, type), cannot
// be encoded again, or whose re-encoding does not decode and re-encode to the
// same bytes. A rejected packet must leave the output untouched.
//
//   swarmlio_packet_decoder_fuzz --write_seeds=DIR   writes the seed corpus, exits
//   swarmlio_packet_decoder_fuzz -runs=1000000 CORPUS_DIR SEED_DIR
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "swarmlio/net/packet_codec.h"
#include "tools/fuzz/fuzz_input.h"
#include "tools/fuzz/seed_corpus.h"

namespace {

using swarmlio::Status;
namespace net = swarmlio::net;

constexpr uint32_t kUntouched = 0xDEADBEEF;

[[noreturn]] void Bug(const char* what, const std::string& detail) {
  std::fprintf(stderr, "packet_decoder_fuzz: BUG: %s %s\n", what, detail.c_str());
  std::abort();
}

/// Encodes `packet`'s message again with its sequence number.
std::vector<uint8_t> Reencode(const net::DecodedPacket& packet) {
  std::vector<uint8_t> bytes;
  const Status s =
      swarmlio::fuzz::FuzzCodec().Encode(packet.message, packet.header.sequence, &bytes);
  if (!s.ok()) Bug("a decoded message does not encode:", s.message());
  return bytes;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const char* const kFlag = "--write_seeds=";
  for (int i = 1; i < *argc; ++i) {
    const char* arg = (*argv)[i];
    if (std::strncmp(arg, kFlag, std::strlen(kFlag)) != 0) continue;
    const Status s = swarmlio::fuzz::WriteSeedCorpus(arg + std::strlen(kFlag));
    if (!s.ok()) {
      std::fprintf(stderr, "packet_decoder_fuzz: %s\n", s.message().c_str());
      std::exit(1);
    }
    std::exit(0);
  }
  (void)swarmlio::fuzz::FuzzCodec();  // libsodium initialised before the first input
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> packet;
  if (!swarmlio::fuzz::PacketFromInput(data, size, &packet)) return 0;
  const net::PacketCodec& codec = swarmlio::fuzz::FuzzCodec();

  net::DecodedPacket decoded;
  decoded.header.sequence = kUntouched;
  const Status status = codec.Decode(packet.data(), packet.size(), &decoded);
  if (!status.ok()) {
    if (decoded.header.sequence != kUntouched) {
      Bug("a rejected packet changed the output:", status.message());
    }
    return 0;
  }
  const Status check = net::CheckMessage(decoded.message);
  if (!check.ok()) Bug("a decoded message fails CheckMessage:", check.message());
  if (net::SenderOf(decoded.message) != decoded.header.sender_id ||
      net::TypeOf(decoded.message) != decoded.header.type) {
    Bug("a decoded message disagrees with its header", "");
  }
  // Encode(Decode(.)) must be a fixed point: its bytes decode and re-encode to
  // themselves.
  const std::vector<uint8_t> once = Reencode(decoded);
  net::DecodedPacket again;
  const Status redecoded = codec.Decode(once.data(), once.size(), &again);
  if (!redecoded.ok()) Bug("a re-encoded message does not decode:", redecoded.message());
  if (Reencode(again) != once) Bug("re-encoding is not stable", "");
  return 0;
}
