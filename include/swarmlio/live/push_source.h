// PushSource: sensor records pushed by a driver, e.g. the ROS node's
// subscriber callbacks (tools/ros), released to a LiveDrone's input thread
// (record_source.h, docs/online.md "ROS node").
//
// Two streams, IMU and LiDAR, arrive in any interleaving (two subscriptions,
// two TCP connections). Each stream's stamps are non-decreasing; the IMU
// stream has passed its last stamp, the LiDAR stream the end of its last
// scan (stamp + the largest point offset: the next scan starts after it, an
// overlapping scan is dropped by the odometry offline and live alike). A
// pushed record waits in a buffer; the buffer's first record in (stamp, IMU
// before scan, push order) is released when
//   - ordering kStamp (exact): the other stream has passed its stamp, so
//     nothing earlier can come from it. An IMU sample within a scan goes as
//     soon as that scan arrives, but one after the scan's end waits for the
//     next scan (about one scan period), and the scan's odometry needs such
//     a sample: odometry comes out about one scan period after the scan end.
//   - ordering kImuFirst (low latency): an IMU sample goes at once (nothing
//     earlier can come from its own stream); a scan when the IMU stream has
//     passed its stamp, as in kStamp. The scan waits for nothing it does not
//     need anyway (the odometry processes it once the IMU passes its end),
//     and every IMU sample up to its stamp precedes it, as in the bag order;
//     only IMU samples after its stamp may precede it too.
//   - or, either ordering: it has waited max_wait_ms on the clock (the other
//     stream is late or silent; a bounded wait), or the buffer holds
//     max_buffered_records records, or Close() was called.
// So in kStamp, as long as no stream lags the other by more than
// max_wait_ms, the records come out in exactly the order BagReader merges a
// bag of the same messages (stamp order, IMU first on ties) whatever the
// interleaving. In kImuFirst each stream comes out in its stamp order and a
// scan after every IMU sample up to its stamp; the odometry (lio::Odometry
// buffers a scan until the IMU passes its end and consumes IMU in stamp
// order) gives the same estimate, but swarm messages are delivered against
// IMU stamps that run up to a scan period ahead of the scan being processed
// (docs/online.md "ROS node", ordering).
//
// Time line: the sensor time line is the records' stamps (for the ROS node
// the message header stamps, ROS time). The mapping to the clock is anchored
// at the first released record: its stamp <-> the clock time it was pushed.
//
// Drop policy (as the bag playback's input: whole scans, never IMU samples
// for lack of room): a scan pushed while max_buffered_scans scans wait is
// dropped; PushImu blocks while the buffer is full (back-pressure on the
// driver) instead of dropping. A record that cannot be delivered in order is
// dropped as late: in kStamp one stamped before any released record (its
// stream lagged more than max_wait_ms), in kImuFirst one stamped before a
// released record of its own stream. Everything is counted in stats().
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/live/record_source.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::live {

/// The release rule (above): kStamp = the bag reader's order exactly, IMU
/// held up to a scan period; kImuFirst = IMU released on arrival.
enum class PushOrdering { kStamp, kImuFirst };

}  // namespace swarmlio::live

namespace swarmlio::config {
template <>
struct EnumTraits<live::PushOrdering> {
  static constexpr std::array<std::pair<live::PushOrdering, const char*>, 2> kNames{
      {{live::PushOrdering::kStamp, "stamp"}, {live::PushOrdering::kImuFirst, "imu_first"}}};
};
}  // namespace swarmlio::config

namespace swarmlio::live {

struct PushSourceOptions {
  // Exact by default for a library user; the ROS node defaults to kImuFirst
  // (its --ordering flag), whose odometry equals the exact order's.
  PushOrdering ordering = PushOrdering::kStamp;
  double max_wait_ms = 500.0;       // a record waits at most this long for the other stream
                                    // to pass its stamp [ms] (> scan period + transport delay)
  int max_buffered_records = 8192;  // IMU samples and scans waiting; PushImu blocks beyond
  int max_buffered_scans = 8;       // scans waiting; a new scan beyond is dropped whole

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("ordering", ordering,
      FieldSpec::Doc("stamp (the bag reader's order exactly; IMU held up to a scan period) or "
                     "imu_first (IMU released on arrival, a scan once the IMU passed its stamp)"));
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
  int64_t imu_late = 0;             // dropped: stamped before a released record (kImuFirst:
                                    // of its own stream)
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
  // The ordering lets `key` go without waiting for the other stream (only
  // kImuFirst's IMU samples).
  bool ReleasedOnArrival(const Key& key) const;
  // `key` cannot be released in order any more (see "late" above).
  bool Late(const Key& key) const;
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
  bool has_released_stream_[kNumStreams] = {false, false};
  int64_t last_released_ns_[kNumStreams] = {0, 0};  // per stream
  bool closed_ = false;
  bool interrupted_ = false;
  PushSourceStats stats_;
};

}  // namespace swarmlio::live
