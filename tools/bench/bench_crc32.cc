// The CRC-32 every MCAP read computes over each chunk and the whole data
// section (src/io/crc32.h): zlib's crc32_z against Intel ISA-L's
// crc32_gzip_refl (the same value) on 1 MiB buffers, the size of the chunks
// our writer makes, at an aligned and an unaligned start.
//
//   build/tools/bench/bench_crc32 --benchmark_min_time=1
#include <benchmark/benchmark.h>
#include <isa-l/crc.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "src/io/crc32.h"

namespace {

constexpr size_t kBytes = size_t{1} << 20;

const std::vector<uint8_t>& Buffer() {
  static const std::vector<uint8_t> bytes = [] {
    std::mt19937 random(1);
    std::vector<uint8_t> b(kBytes + 64);
    for (uint8_t& x : b) x = static_cast<uint8_t>(random());
    return b;
  }();
  return bytes;
}

// state.range(0): offset of the first byte (0: 64-byte aligned heap block).
void BM_ZlibCrc32(benchmark::State& state) {
  const uint8_t* data = Buffer().data() + state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(crc32_z(0, data, kBytes));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * kBytes));
}

void BM_IsalCrc32(benchmark::State& state) {
  const uint8_t* data = Buffer().data() + state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(crc32_gzip_refl(0, data, kBytes));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * kBytes));
}

// What the reader calls (ISA-L behind one function).
void BM_SwarmlioCrc32(benchmark::State& state) {
  const uint8_t* data = Buffer().data() + state.range(0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(swarmlio::io::internal::Crc32(data, kBytes));
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * kBytes));
}

// The CRC of a buffer, then scalar float work on it compiled for baseline
// x86-64 (SSE), as a message decoder does after a chunk's CRC: ISA-L called
// directly leaves the upper vector halves in use (no vzeroupper), which
// slows that SSE code down; swarmlio's Crc32 clears them.
template <uint32_t (*kCrc)(const uint8_t*, size_t)>
void CrcThenDecode(benchmark::State& state) {
  const uint8_t* data = Buffer().data();
  std::vector<float> floats(kBytes / sizeof(float));
  for (auto _ : state) {
    benchmark::DoNotOptimize(kCrc(data, kBytes));
    std::memcpy(floats.data(), data, kBytes);
    double sum = 0.0;
    for (const float f : floats) sum += static_cast<double>(f) * 0.5 + 1.0;
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * kBytes));
}

uint32_t IsalDirect(const uint8_t* data, size_t size) { return crc32_gzip_refl(0, data, size); }
uint32_t Swarmlio(const uint8_t* data, size_t size) {
  return swarmlio::io::internal::Crc32(data, size);
}

BENCHMARK(BM_ZlibCrc32)->Arg(0)->Arg(3);
BENCHMARK(BM_IsalCrc32)->Arg(0)->Arg(3);
BENCHMARK(BM_SwarmlioCrc32)->Arg(0)->Arg(3);
BENCHMARK(CrcThenDecode<IsalDirect>)->Name("BM_IsalCrc32ThenSseWork");
BENCHMARK(CrcThenDecode<Swarmlio>)->Name("BM_SwarmlioCrc32ThenSseWork");

}  // namespace

int main(int argc, char** argv) {
  // The candidates must agree before they are timed.
  const uint8_t* data = Buffer().data() + 3;
  if (static_cast<uint32_t>(crc32_z(0, data, kBytes)) != crc32_gzip_refl(0, data, kBytes)) {
    std::fprintf(stderr, "error: zlib and ISA-L disagree\n");
    return EXIT_FAILURE;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return EXIT_FAILURE;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return EXIT_SUCCESS;
}
