// The stage stopwatch of the timing reports: seconds since a steady-clock
// time point (never the wall clock, never an input to the estimate).
#pragma once

#include <chrono>

namespace swarmlio {

using StopwatchClock = std::chrono::steady_clock;

/// Seconds elapsed since `start` on the steady clock.
inline double SecondsSince(StopwatchClock::time_point start) {
  return std::chrono::duration<double>(StopwatchClock::now() - start).count();
}

}  // namespace swarmlio
