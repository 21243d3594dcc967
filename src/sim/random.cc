#include "swarmlio/sim/random.h"

namespace swarmlio::sim {
namespace {

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

uint64_t DeriveSeed(uint64_t seed, uint64_t drone, uint64_t stream) {
  return SplitMix64(SplitMix64(SplitMix64(seed) ^ drone) ^ stream);
}

double CounterUniform(uint64_t key, uint64_t item, uint64_t draw) {
  // The top 53 bits, shifted to (0, 1] so that log() of it is finite.
  return static_cast<double>((DeriveSeed(key, item, draw) >> 11) + 1) * 0x1.0p-53;
}

}  // namespace swarmlio::sim
