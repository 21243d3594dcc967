// swarm::DroneEstimator: everything one drone runs (paper Fig. 2), the
// component the offline replay, the live process, the ROS node and the tests
// drive. A manager over collaborators, called top-down once per scan
// (docs/architecture.md walks one scan and one message through it):
//
//   1. the odometry (lio::Odometry) queues the inputs and hands out each scan
//      once IMU data cover it: preprocessed, propagated, undistorted;
//   2. the detector (teammate::TeammateDetector) finds, tracks and
//      identifies teammates in the scan's reflective points at the
//      predicted pose;
//   3. the teammate registry adds the extrinsic blocks T_Gi_Gj of newly
//      identified teammates to the state and removes lost ones;
//   4. each updater (active, passive, gravity; one per measurement type)
//      turns its pending inputs into residual terms through the gate;
//   5. the odometry's back end (filter or window) updates, and the map takes
//      the scan without the teammates' points;
//   6. the broadcaster queues the scan's messages; the output is returned.
// Received messages go to the inbox, which hands each to its owner at once.
//
// Inputs: Add(SensorRecord): IMU samples, LiDAR scans (own clock), received
// messages (their arrival time in the own clock). Outputs: PopOutputs,
// PopMessages. Drivers run it through driver::DroneDriver. No I/O,
// no clock reads, no threads inside. docs/swarm.md has the math and policies.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/odometry.h"
#include "swarmlio/net/clock_sync.h"
#include "swarmlio/net/message_channel.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/swarm/sensor_record.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/airframe.h"
#include "swarmlio/teammate/teammate_detector.h"

namespace swarmlio::swarm {

struct DroneEstimatorOptions {
  lio::OdometryOptions odometry;
  teammate::TeammateDetectorOptions teammate;
  SwarmOptions swarm;
  /// This drone's own body, announced to the teammates every
  /// swarm.experimental.airframe_period_s (YAML `airframe:` of a drone entry).
  teammate::AirframeDescription airframe;
  std::string Validate() const;
};

/// One identified teammate's state in this drone's frame G_i at a scan end.
struct TeammateEstimate {
  int drone_id = -1;
  GlobalExtrinsic T_Gi_Gj;  // from the state
  Eigen::Matrix<double, 6, 6> extrinsic_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool have_pose = false;  // a recent enough broadcast state exists
  Eigen::Quaterniond q_Gi_bj = Eigen::Quaterniond::Identity();  // j's body in G_i
  Eigen::Vector3d p_bj_in_Gi = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_bj_in_Gi = Eigen::Vector3d::Zero();
  bool seen = false;             // a LiDAR observation of j in this scan
  int active_observations = 0;   // fused in this scan
  int passive_observations = 0;  // fused in this scan
};

/// How a teammate was identified.
struct IdentificationEvent {
  int drone_id = -1;
  int64_t stamp_ns = 0;   // own clock
  std::string method;     // "trajectory_match", "teammate_match" (it identified me) or
                          // "graph" (through teammate via_drone_id's own match)
  int via_drone_id = -1;  // "graph": the teammate whose T_Gj_Gk was composed
  double mean_residual_m = 0.0;
  GlobalExtrinsic initial_T_Gi_Gj;
};

struct DroneOutput {
  lio::ScanOutput ego;
  std::vector<TeammateEstimate> teammates;           // every teammate in the state
  std::vector<IdentificationEvent> identifications;  // in this scan
  std::vector<int> removed_teammates;                // left the state in this scan
  int active_observations = 0;                       // fused
  int passive_observations = 0;                      // fused
  int gravity_alignments = 0;                        // teammates' gravity fused
  int rejected_observations = 0;                     // gated out or unusable (no recent message)
  bool extrinsics_frozen = false;                    // degeneracy policy applied
  int num_detector_points = 0;                       // full-resolution points given to the detector
};

struct DroneEstimatorCounters {
  int64_t messages_received = 0;
  int64_t messages_ignored = 0;   // own, unknown type, non-finite, stale, a TimeSync for another
                                  // drone, or an invalid airframe
  int64_t teammate_restarts = 0;  // session_start changed
  int64_t messages_unsynchronized = 0;  // states of a teammate whose clock offset is not known yet
  int64_t identifications = 0;
  int64_t teammates_removed = 0;
  int64_t active_fused = 0;
  int64_t passive_fused = 0;
  int64_t passive_repeated = 0;   // of passive_fused: sent again after the first message (lost)
  int64_t repeats_duplicate = 0;  // observations of this drone received twice: used once
  // Ignored: T_Gj_Gi from before this session, T_Gj_Gk from before k restarted.
  int64_t extrinsics_stale = 0;
  int64_t gravity_fused = 0;
  int64_t observations_rejected = 0;
  int64_t front_end_errors = 0;
  // What this drone broadcast, wire bytes by content (IP/UDP headers in the
  // state's and the extrinsic broadcasts' shares), and the observations the
  // byte budget left out (docs/swarm.md "Broadcast budget").
  int64_t sent_state_bytes = 0;
  int64_t sent_echo_bytes = 0;  // state echoes and offset reports
  int64_t sent_observation_bytes = 0;
  int64_t sent_repeat_bytes = 0;
  int64_t sent_extrinsic_bytes = 0;
  int64_t sent_airframe_bytes = 0;  // the own airframe's announcements
  int64_t observations_unsent = 0;
};

/// One line for the tools' summaries: "broadcast: N B states, ... B
/// extrinsics, ... B airframe" (the sent_* counters and observations_unsent), starting with
/// `indent`, ending with a newline.
std::string FormatBroadcastCounters(const DroneEstimatorCounters& c, const std::string& indent);

class DroneEstimator {
 public:
  static Status Create(int self_id,
                       const DroneEstimatorOptions& options,
                       const LidarOptions& lidar,
                       std::unique_ptr<DroneEstimator>* estimator);
  ~DroneEstimator();

  /// One input, the only entry: an IMU sample, a scan, or a received message
  /// (arrival time in this drone's clock). Processes every scan the IMU now
  /// covers (PopOutputs). A data problem the estimator skipped (a NaN sample,
  /// an out-of-order scan) is returned; the estimator stays usable. Bad or
  /// own messages are counted and ignored (Ok).
  Status Add(const SensorRecord& record);
  /// End of the log: processes the waiting scans.
  Status Flush();
  /// Ablation: fuse active and passive observations (per the options) or
  /// none (teammates are still identified and reported).
  void SetFusion(bool fuse) { fusion_enabled_ = fuse; }

  void PopOutputs(std::vector<DroneOutput>* outputs);
  /// Messages to broadcast, produced since the last call (one EgoStateMessage
  /// per scan, the extrinsics, the clock-synchronisation requests and
  /// responses). Send them now: the TimeSync stamps are the newest sensor
  /// stamp given to this estimator (the driver's "now" on this drone's clock;
  /// a deterministic function of the inputs, so an offline re-run of a
  /// recorded live run reproduces it).
  void PopMessages(std::vector<net::SwarmMessage>* messages);
  /// Clock synchronisation with the teammates (null when synchronize_clocks is off).
  const net::ClockSync* clock_sync() const;

  int self_id() const { return self_id_; }
  /// The component's own odometry (its unit tests); drivers use the
  /// accessors below.
  const lio::Odometry& odometry() const { return *odometry_; }
  /// What the drivers report of the odometry: its counters, the IMU
  /// initialization (initialization() is valid once initialized()), the map.
  const lio::OdometryCounters& odometry_counters() const { return odometry_->counters(); }
  bool initialized() const { return odometry_->initialized(); }
  const std::string& initialization_error() const { return odometry_->initialization_error(); }
  const lio::ImuInitialization& initialization() const { return odometry_->initialization(); }
  size_t map_size() const { return odometry_->map_size(); }
  std::vector<Eigen::Vector3d> MapPoints() const { return odometry_->MapPoints(); }
  const teammate::TeammateDetector& detector() const { return *detector_; }
  const DroneEstimatorCounters& counters() const { return counters_; }
  const DroneEstimatorOptions& options() const { return options_; }

 private:
  struct Parts;
  DroneEstimator(int self_id, const DroneEstimatorOptions& options, const LidarOptions& lidar);

  // The three kinds of Add.
  Status AddImu(const ImuSample& sample);
  Status AddScan(const LidarScan& scan);
  Status AddMessage(const net::ReceivedMessage& message);

  // Every scan the odometry hands out, through the pass; the first error.
  Status ProcessReadyScans(bool flush);
  // One scan, top-down (steps 2-6 of the header comment).
  Status ProcessScan(lio::ScanContext* scan);
  // Steps 2-4: detection, the registry, the updaters' terms into `request`.
  Status FrontEnd(lio::ScanContext* scan, lio::UpdateRequest* request);
  // Step 6: the output of the scan and its broadcast.
  void Finish(const lio::ScanContext& scan, lio::ScanOutput ego);

  int self_id_;
  DroneEstimatorOptions options_;
  LidarOptions lidar_;
  std::unique_ptr<lio::Odometry> odometry_;
  std::unique_ptr<teammate::TeammateDetector> detector_;
  DroneEstimatorCounters counters_;
  std::unique_ptr<Parts> parts_;
  bool fusion_enabled_ = true;
};

}  // namespace swarmlio::swarm
