// PushSource: sensor records pushed by a driver, e.g. the ROS node's
// subscriber callbacks (tools/ros), released to a LiveDrone's input thread
// in a deterministic order (record_source.h, docs/online.md "ROS node").
//
// Two streams, IMU and LiDAR, arrive in any interleaving (two subscriptions,
// two TCP connections). A pushed record waits in a buffer; the buffer's
// first record in (stamp, IMU before scan, push order) is released when
//   - the other stream has passed its stamp: nothing earlier can come from
//     it. Each stream's stamps are non-decreasing; the IMU stream has passed
//     its last stamp, the LiDAR stream the end of its last scan (stamp + the
//     largest point offset: the next scan starts after it, an overlapping
//     scan is dropped by the odometry offline and live alike). So an IMU
//     sample within a scan is released as soon as that scan arrives, not
//     one scan period later; or
//   - it has waited max_wait_ms on the clock (the other stream is late or
//     silent; a bounded wait), or
//   - the buffer holds max_buffered_records records, or Close() was called.
// So, as long as no stream lags the other by more than max_wait_ms, the
// records come out in exactly the order BagReader merges a bag of the same
// messages (stamp order, IMU first on ties) whatever the interleaving.
//
// Time line: the sensor time line is the records' stamps (for the ROS node
// the message header stamps, ROS time). The mapping to the clock is anchored
// at the first released record: its stamp <-> the clock time it was pushed.
//
// Drop policy (as the bag playback's input: whole scans, never IMU samples
// for lack of room): a scan pushed while max_buffered_scans scans wait is
// dropped; PushImu blocks while the buffer is full (back-pressure on the
// driver) instead of dropping. A record stamped before one already released
// (its stream lagged more than max_wait_ms) cannot be delivered in order
// and is dropped as late. Everything is counted in stats().
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>

#include "swarmlio/config/option_fields.h"
#include "swarmlio/live/record_source.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::live {

struct PushSourceOptions {
  double max_wait_ms = 500.0;       // a record waits at most this long for the other stream
                                    // to pass its stamp [ms] (> scan period + transport delay)
  int max_buffered_records = 8192;  // IMU samples and scans waiting; PushImu blocks beyond
  int max_buffered_scans = 8;       // scans waiting; a new scan beyond is dropped whole

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("max_wait_ms", max_wait_ms,
      FieldSpec::InRange(0.0, 60000.0, "ms", "wait for the other stream to pass a stamp"));
    v("max_buffered_records", max_buffered_records,
      FieldSpec::InRange(16, 1 << 20, "", "records waiting to be ordered"));
    v("max_buffered_scans", max_buffered_scans,
      FieldSpec::InRange(1, 1000, "", "scans waiting to be ordered; more are dropped"));
  }
  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

struct PushSourceStats {
  int64_t imu_pushed = 0;
  int64_t scans_pushed = 0;
  int64_t released = 0;
  int64_t released_by_timeout = 0;  // the other stream had not passed the stamp (waited
                                    // max_wait_ms, or a full buffer)
  int64_t imu_late = 0;             // dropped: stamped before a released record
  int64_t scans_late = 0;
  int64_t scans_dropped_full = 0;   // max_buffered_scans were waiting
  int64_t imu_push_waits = 0;       // PushImu blocked on a full buffer
};

class PushSource : public RecordSource {
 public:
  /// `clock` (not owned) times the bounded wait; the LiveDrone's clock.
  static Status Create(const PushSourceOptions& options, const Clock* clock,
                       std::unique_ptr<PushSource>* source);
  ~PushSource() override;

  /// Any thread. PushImu blocks while the buffer is full. After Close() or
  /// Interrupt() pushes are ignored.
  void PushImu(const ImuSample& imu);
  void PushScan(LidarScan scan);
  /// The input ended: what is buffered is released in order, then the end.
  void Close();

  PushSourceStats stats() const;  // any thread

  Status Start(SourceStart* start, bool* has_record) override;
  Status Next(const SensorTimeMapping& mapping, io::BagRecord* record, bool* has_record) override;
  void Interrupt() override;
  bool paced_by_rate() const override { return false; }

 private:
  enum Stream { kImu = 0, kLidar = 1, kNumStreams = 2 };
  // Release order: stamp, then IMU before scan, then push order.
  using Key = std::tuple<int64_t, int, uint64_t>;
  struct Entry {
    io::BagRecord record;
    int64_t push_clock_ns = 0;
  };

  PushSource() = default;
  // `passed_ns`: the stream will push nothing stamped before it.
  void Push(Stream stream, int64_t stamp_ns, int64_t passed_ns, io::BagRecord record);
  // Blocks (lock held) until the first record may be released; false at the
  // end (closed and empty) or after Interrupt().
  bool WaitReleasable(std::unique_lock<std::mutex>* lock);
  bool Releasable(int64_t now_ns) const;
  // Every other stream has pushed a record stamped at or after `key`'s.
  bool OthersPassed(const Key& key) const;

  PushSourceOptions options_;
  const Clock* clock_ = nullptr;
  int64_t max_wait_ns_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<Key, Entry> buffer_;
  uint64_t next_seq_ = 0;
  int buffered_scans_ = 0;
  bool has_pushed_[kNumStreams] = {false, false};
  int64_t passed_ns_[kNumStreams] = {0, 0};  // per stream: nothing earlier will come
  bool has_released_ = false;
  Key last_released_{0, 0, 0};
  bool closed_ = false;
  bool interrupted_ = false;
  PushSourceStats stats_;
};

}  // namespace swarmlio::live
