// live::Clock on std::chrono::steady_clock: what swarmlio_live runs on (the
// library itself never reads a clock).
#pragma once

#include <chrono>
#include <thread>

#include "swarmlio/live/clock.h"

namespace swarmlio::tools {

class SteadyClock : public live::Clock {
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

}  // namespace swarmlio::tools
