#include "src/io/crc32.h"

#include <isa-l/crc.h>
#include <zlib.h>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace swarmlio::io::internal {
namespace {

static_assert(sizeof(z_off_t) >= sizeof(uint64_t), "crc32_combine needs a 64-bit z_off_t");

#if defined(__x86_64__)
// ISA-L's AVX-512 CRC returns with the upper halves of the vector registers
// in use (it has no vzeroupper), and the code after it, compiled for
// baseline x86-64 (SSE), then ran several times slower: bench_log_read's
// MCAP pass went from 0.54 s to 0.92 s CPU, most of it in the message
// decoders (perf: DecodeLivoxCustomMsg 5.3x its samples). Clearing them
// after each call, as compilers do after their own AVX code, avoids that.
__attribute__((target("avx"))) void ClearUpperVectorHalves() { _mm256_zeroupper(); }

bool CpuHasAvx() {
  static const bool has_avx = [] {
    __builtin_cpu_init();  // may run before the constructor that does it
    return __builtin_cpu_supports("avx") != 0;
  }();
  return has_avx;
}
#endif

}  // namespace

uint32_t Crc32(const uint8_t* data, size_t size, uint32_t seed) {
  // ISA-L's reflected gzip CRC takes and returns the CRC as zlib does (the
  // XORs with 0xFFFFFFFF inside), so a seed continues a previous value.
  const uint32_t crc = crc32_gzip_refl(seed, data, size);
#if defined(__x86_64__)
  if (CpuHasAvx()) ClearUpperVectorHalves();
#endif
  return crc;
}

uint32_t Crc32Combine(uint32_t crc_a, uint32_t crc_b, uint64_t size_b) {
  return static_cast<uint32_t>(crc32_combine(crc_a, crc_b, static_cast<z_off_t>(size_b)));
}

}  // namespace swarmlio::io::internal
