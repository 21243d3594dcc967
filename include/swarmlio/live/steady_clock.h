// live::Clock on std::chrono::steady_clock: what swarmlio_live and the live
// tests run on. LiveDrone never reads a clock itself; drivers inject this one
// (or an accelerated / fake one).
#pragma once

#include <chrono>
#include <thread>

#include "swarmlio/live/clock.h"

namespace swarmlio::live {

class SteadyClock : public Clock {
 public:
  int64_t NowNs() const override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  void SleepForNs(int64_t duration_ns) const override {
    std::this_thread::sleep_for(std::chrono::nanoseconds(duration_ns));
  }
};

}  // namespace swarmlio::live
