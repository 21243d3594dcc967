// Options of the live process (docs/online.md): playback speed, thread
// hand-off queues and the scan drop policy. Units in the names or comments.
#pragma once

#include <string>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::live {

struct LiveOptions {
  double rate = 1.0;                   // playback speed: sensor seconds per clock second
  double network_poll_period_ms = 2.0; // the network thread polls the socket this often [ms]
  int input_queue_records = 4096;      // input -> estimator: bag records (IMU, scans, poses)
  int max_queued_scans = 4;            // scans waiting in that queue; more: the new scan is dropped
  double max_scan_backlog_s = 0.3;     // a scan taken this late (sensor time behind the
                                       // playback) is dropped instead of processed [s]
  int message_queue_capacity = 1024;   // network -> estimator: received messages
  int outbox_capacity = 256;           // estimator -> network: messages to send
  bool imu_rate_odometry = true;       // propagate the state at every IMU sample
  double start_offset_s = 0.0;         // skip the log's first seconds: playback starts at the
                                       // first record this far after the log's first (a drone
                                       // that joins late or restarts mid-flight) [s]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("rate", rate, FieldSpec::Positive("", "playback speed (1 = real time)").WithMax(1000.0));
    v("network_poll_period_ms", network_poll_period_ms,
      FieldSpec::InRange(0.1, 100.0, "ms", "UDP poll period of the network thread"));
    v("input_queue_records", input_queue_records,
      FieldSpec::InRange(16, 1 << 20, "", "records queued from input to estimator"));
    v("max_queued_scans", max_queued_scans,
      FieldSpec::InRange(1, 1000, "", "scans queued at most; a new scan beyond is dropped"));
    v("max_scan_backlog_s", max_scan_backlog_s,
      FieldSpec::Positive("s", "a scan taken later than this behind playback is dropped")
          .WithMax(60.0));
    v("message_queue_capacity", message_queue_capacity,
      FieldSpec::InRange(1, 1 << 20, "", "received messages queued for the estimator"));
    v("outbox_capacity", outbox_capacity,
      FieldSpec::InRange(1, 1 << 20, "", "messages queued for sending"));
    v("imu_rate_odometry", imu_rate_odometry,
      FieldSpec::Doc("propagated pose at every IMU sample (flight controller feed)"));
    v("start_offset_s", start_offset_s,
      FieldSpec::InRange(0.0, 1e6, "s", "skip the log's first seconds (late join, restart)"));
  }
  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

}  // namespace swarmlio::live
