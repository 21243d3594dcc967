// Time in swarmlio: every stamp is int64 nanoseconds (logs round-trip bit for
// bit, and a stamp keeps its nanoseconds however far from the epoch it is).
// Durations in options are double seconds (SI, named *_s). These are the only
// conversions between the two.
#pragma once

#include <cmath>
#include <cstdint>

namespace swarmlio {

constexpr int64_t kNanosecondsPerSecond = 1'000'000'000;

/// A stamp or an interval [ns] in seconds. Correctly rounded (division, not
/// multiplication by 1e-9), so every module converting this way gets
/// bit-identical seconds.
constexpr double ToSeconds(int64_t ns) { return static_cast<double>(ns) / 1e9; }

/// `to_ns - from_ns` in seconds (the difference is taken exactly in ns first).
constexpr double SecondsBetween(int64_t from_ns, int64_t to_ns) { return ToSeconds(to_ns - from_ns); }

/// A duration [s] to the nearest nanosecond.
inline int64_t ToNanoseconds(double seconds) { return std::llround(seconds * 1e9); }

}  // namespace swarmlio
