// LiveDrone: one drone of the live swarm in real time (docs/online.md). It
// takes the drone's sensor records from a RecordSource (record_source.h):
// its bag played at `rate` x real time against an injected Clock
// (BagPlaybackSource, the default), or records pushed by a driver such as the
// ROS node (PushSource); runs its swarm::DroneEstimator through the drivers'
// one loop (driver::DroneDriver) and talks to the
// teammates through a real net::Transport (UdpTransport), with three threads:
//
//   input      takes each record from the source when it is due (bag:
//              SensorTimeMapping) or released (push: stamp order, or IMU
//              first, push_source.h); bounded
//              queue to the estimator; a scan beyond max_queued_scans
//              waiting is dropped (IMU never);
//   estimator  consumes records in the source's order; before a record at stamp s
//              it waits until the network thread has polled up to s and
//              delivers the received messages with arrival <= s (exactly the
//              offline replay's rule, so a recorded run in stamp order
//              re-runs identically);
//              drops a scan taken more than max_scan_backlog_s late; sends
//              the estimator's messages through the network thread;
//   network    every network_poll_period_ms: sends what the estimator
//              produced, polls the transport (arrival = the clock mapped to
//              the sensor time line), records every datagram to the packet
//              log, decodes and hands the messages over (bounded queue).
//
// The MessageChannel and the transport are used by the network thread only.
// Memory is bounded by the queues; outputs are streamed to the LiveSink.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/live/clock.h"
#include "swarmlio/live/live_options.h"
#include "swarmlio/live/live_sink.h"
#include "swarmlio/live/record_source.h"
#include "swarmlio/net/message_channel.h"
#include "swarmlio/net/swarm_key.h"
#include "swarmlio/net/transport.h"
#include "swarmlio/driver/manifest.h"
#include "swarmlio/swarm/drone_estimator.h"

namespace swarmlio::live {

struct LiveSetup {
  driver::DroneInput drone;  // bag (unless `source`), sensors, estimator options
  int drone_id = 0;          // swarm id (index in the manifest; the same on every drone)
  net::SwarmKey key;         // the swarm's pre-shared key
  net::Transport* transport = nullptr;  // not owned; used by the network thread only
  const Clock* clock = nullptr;         // not owned
  LiveSink* sink = nullptr;             // not owned; may be null
  std::string packet_log_path;          // received datagrams; "" = not recorded
  RecordSource* source = nullptr;       // not owned; null: the drone's bag played back
                                        // (BagPlaybackSource); a pushed source needs
                                        // rate 1 and start_offset_s 0
};

struct LiveStats {
  int64_t records_played = 0;        // taken from the source by the input thread
  int64_t imu_samples = 0;
  int64_t scans_played = 0;
  int64_t scans_processed = 0;       // estimator outputs
  int64_t scans_held_by_initialization = 0;  // of those: held by the in-flight
                                             // initialization (lio::ScanOutput)
  int64_t scans_dropped_queue = 0;   // ScanDropReason::kQueueFull
  int64_t scans_dropped_backlog = 0; // ScanDropReason::kBacklog
  int64_t input_stalls = 0;          // the input thread waited on a full queue
  int64_t imu_poses = 0;             // IMU-rate odometry outputs
  int64_t first_imu_pose_ns = 0;     // their first and last stamps (sensor clock; the
  int64_t last_imu_pose_ns = 0;      // summaries' output rate)
  int64_t messages_sent = 0;
  int64_t send_errors = 0;
  int64_t outgoing_dropped_queue = 0;// outbox full (not sent)
  int64_t messages_delivered = 0;    // handed to the estimator
  int64_t messages_dropped_queue = 0;// message queue full (not delivered)
  int64_t datagrams_logged = 0;      // packet log records
  net::ChannelStats channel;         // received, rejected, duplicates, own packets
  int64_t estimator_warnings = 0;    // data problems the estimator skipped
  std::string first_warning;
  int64_t sensor_start_ns = 0;       // first record's stamp
  int64_t sensor_end_ns = 0;         // last record's stamp
  int64_t clock_elapsed_ns = 0;      // whole run on the clock
  int64_t clock_start_ns = 0;        // Clock::NowNs() when the first record played: with
                                     // sensor_start_ns and the rate, the playback's mapping
                                     // (processes on one machine share the steady clock, so
                                     // their true clock offsets follow, docs/online.md)
};

class LiveDrone {
 public:
  /// Opens the bag (reads its first record) unless setup.source is given,
  /// creates the estimator, codec and packet log. Errors name the drone, the
  /// option or the file.
  static Status Create(const LiveSetup& setup, const LiveOptions& options,
                       std::unique_ptr<LiveDrone>* drone);
  ~LiveDrone();
  LiveDrone(const LiveDrone&) = delete;
  LiveDrone& operator=(const LiveDrone&) = delete;

  /// Plays the whole bag / takes records until the source ends (or until
  /// Stop()), then flushes the estimator and joins the threads. Blocks first
  /// until the source has its first record (the sensor time line's start).
  /// Returns the first error (bag read, transport, packet log); what was
  /// processed until then is kept. Call once.
  Status Run();
  /// Asks Run() to finish early (any thread, e.g. a signal watcher).
  void Stop();

  /// After Run().
  const LiveStats& stats() const;
  const swarm::DroneEstimator& estimator() const;
  const SensorTimeMapping& mapping() const;

 private:
  struct Impl;
  LiveDrone() = default;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::live
