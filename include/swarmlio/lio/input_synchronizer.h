// InputSynchronizer: the IMU/scan time alignment of one drone's odometry.
// Scans wait until an IMU sample at or after their last point has arrived
// (or the log ends), in arrival order; a scan that does not end after the
// previous one is refused, and the oldest waiting scan is dropped when more
// than `max_queued_scans` wait. It only orders and holds inputs: what a
// scan or a sample does to the state is lio::Odometry's.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::lio {

/// A scan waiting for the IMU to cover it.
struct PendingScan {
  LidarScan scan;
  int64_t end_ns = 0;  // its last point's time
};

class InputSynchronizer {
 public:
  /// `max_queued_scans` >= 1 (validated with the odometry options).
  explicit InputSynchronizer(int max_queued_scans) : max_queued_scans_(max_queued_scans) {}

  /// An IMU sample's stamp (after the IMU time offset): InvalidArgument, and
  /// nothing changes, unless it is after the previous sample's.
  Status AddImuStamp(int64_t stamp_ns, int64_t raw_stamp_ns);
  bool have_imu() const { return have_imu_; }
  int64_t newest_imu_ns() const { return newest_imu_ns_; }

  /// Queues a scan. InvalidArgument (not queued) when it does not end after
  /// the previous scan (queued or processed); OutOfRange when the queue
  /// overflowed: the scan is queued and the oldest one dropped.
  Status AddScan(PendingScan scan);

  /// Takes the oldest scan when the IMU covers its end, or any with `flush`.
  bool PopReady(bool flush, PendingScan* scan);
  /// The processed scan's end: the next scan must end after it.
  void MarkProcessed(int64_t end_ns);

  /// Forgets the queued scans and the processed one (a restart of the
  /// odometry); the IMU stamp stays.
  void ClearScans();
  /// Replaces the queue (the in-flight initialization re-plays its scans).
  void ReplayScans(const std::vector<PendingScan>& scans);

  size_t num_queued() const { return queue_.size(); }

 private:
  int max_queued_scans_;
  std::deque<PendingScan> queue_;
  bool have_imu_ = false;
  int64_t newest_imu_ns_ = 0;
  bool have_processed_ = false;
  int64_t processed_end_ns_ = 0;
};

}  // namespace swarmlio::lio
