// LiveSink: where the live process's outputs go (the tool writes files, a
// test keeps them). Every call comes from the estimator thread, in order;
// implementations must return quickly (they delay the estimator).
#pragma once

#include <cstdint>

#include "swarmlio/live/imu_rate_odometry.h"
#include "swarmlio/swarm/drone_estimator.h"

namespace swarmlio::live {

/// Timing of one processed scan on the process's clock [ns].
struct ScanLatency {
  int64_t scan_end_clock_ns = 0;  // when the scan end was reached in playback
  int64_t output_clock_ns = 0;    // when the estimator produced the output
  // Produced by the final flush (the input ended before an IMU sample past
  // the scan end came): its latency is the input's end, not the pipeline's.
  bool at_flush = false;
  /// output - scan end: waiting for the IMU sample after the scan end, queues
  /// and processing (the odometry-out latency a consumer sees).
  int64_t latency_ns() const { return output_clock_ns - scan_end_clock_ns; }
};

enum class ScanDropReason {
  kQueueFull,  // max_queued_scans scans were already waiting (input thread)
  kBacklog,    // taken more than max_scan_backlog_s behind playback (estimator thread)
};

class LiveSink {
 public:
  virtual ~LiveSink() = default;
  virtual void OnScan(const swarm::DroneOutput& /*output*/, const ScanLatency& /*latency*/) {}
  virtual void OnScanDropped(int64_t /*scan_stamp_ns*/, ScanDropReason /*reason*/) {}
  virtual void OnImuPose(const ImuRatePose& /*pose*/) {}
};

}  // namespace swarmlio::live
