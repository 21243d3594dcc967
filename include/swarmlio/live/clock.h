// The clock the live process runs on, injected: the library never reads the
// wall clock itself. The tool passes a steady clock, tests may pass an
// accelerated or fake one. SensorTimeMapping converts between that clock and
// the drone's sensor time line (docs/online.md, "Time").
#pragma once

#include <cmath>
#include <cstdint>

namespace swarmlio::live {

class Clock {
 public:
  virtual ~Clock() = default;
  /// Monotonic time [ns] (any origin). Called from several threads.
  virtual int64_t NowNs() const = 0;
  /// Sleeps about `duration_ns` (> 0) of this clock's time. Several threads.
  virtual void SleepForNs(int64_t duration_ns) const = 0;
};

/// sensor = sensor_start_ns + (clock - clock_start_ns) * rate, and back.
struct SensorTimeMapping {
  int64_t sensor_start_ns = 0;  // stamp of the first played record [ns]
  int64_t clock_start_ns = 0;   // Clock::NowNs() when it was played [ns]
  double rate = 1.0;            // playback speed (sensor s per clock s)

  int64_t ToSensorNs(int64_t clock_ns) const {
    return sensor_start_ns +
           static_cast<int64_t>(std::llround(static_cast<double>(clock_ns - clock_start_ns) * rate));
  }
  int64_t ToClockNs(int64_t sensor_ns) const {
    return clock_start_ns +
           static_cast<int64_t>(std::llround(static_cast<double>(sensor_ns - sensor_start_ns) / rate));
  }
};

}  // namespace swarmlio::live
