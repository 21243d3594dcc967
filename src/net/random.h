// Deterministic random numbers for the simulated network.
//
// std::mt19937_64 is specified bit for bit by the C++ standard; the standard
// distributions are not (libstdc++ and libc++ differ), and Box-Muller would
// depend on libm's log/cos. So the distributions here use only integer and
// IEEE double arithmetic (+, *, comparisons), which every conforming platform
// evaluates identically: the same seed gives the same numbers everywhere.
#pragma once

#include <cstdint>
#include <random>

namespace swarmlio::net::internal {

/// SplitMix64 step (Steele et al. 2014): mixes seeds into independent streams.
inline uint64_t SplitMix64(uint64_t* state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

class DeterministicRandom {
 public:
  explicit DeterministicRandom(uint64_t seed) : engine_(seed) {}

  /// Uniform in [0, 1), 53 random bits.
  double Uniform01() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  /// True with probability p (p <= 0 never, p >= 1 always).
  bool Bernoulli(double p) { return Uniform01() < p; }

  /// Approximately standard normal: Irwin-Hall sum of 12 uniforms minus 6
  /// (mean 0, variance 1, support [-6, 6], kurtosis 2.9 instead of 3).
  double StandardNormal() {
    double sum = 0.0;
    for (int i = 0; i < 12; ++i) sum += Uniform01();
    return sum - 6.0;
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace swarmlio::net::internal
