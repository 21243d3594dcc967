// swarm::DroneEstimator: everything one drone runs (paper Fig. 2), the
// component the offline replay, the live process, the ROS node and the tests
// drive. It owns the LiDAR-inertial odometry (lio::Odometry), the teammate
// detector / trackers / identification (teammate::TeammateDetector) and the
// swarm state (T_Gi_Gj blocks in the odometry's state), and takes part in
// the odometry's scan pipeline through lio::ScanStageHooks:
//
//   front end: undistort the full scan (with reflectivity), detect, track and
//     identify teammates at the predicted pose; add a T_Gi_Gj block for each
//     newly identified teammate, drop those lost for good; build the active
//     observation factors (this scan's clusters) and the passive ones
//     (received messages in which a teammate saw this drone);
//   update: prior + point-to-plane + active + passive (EsikfUpdate), only the
//     extrinsic blocks of teammates observed in this scan estimated;
//   teammate points are kept out of the map; then the outputs: ego state,
//     every teammate's state in G_i, and the EgoStateMessage to broadcast.
//
// Inputs: IMU samples, LiDAR scans (own clock), received messages (their
// arrival time in the own clock). Outputs: PopOutputs, PopMessages. No I/O,
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
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/teammate_detector.h"

namespace swarmlio::swarm {

struct DroneEstimatorOptions {
  lio::OdometryOptions odometry;
  teammate::TeammateDetectorOptions teammate;
  SwarmOptions swarm;
  std::string Validate() const;
};

/// One identified teammate's state in this drone's frame G_i at a scan end.
struct TeammateEstimate {
  int drone_id = -1;
  GlobalExtrinsic T_Gi_Gj;                                           // from the state
  Eigen::Matrix<double, 6, 6> extrinsic_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool have_pose = false;  // a recent enough broadcast state exists
  Eigen::Quaterniond q_Gi_bj = Eigen::Quaterniond::Identity();  // j's body in G_i
  Eigen::Vector3d p_bj_in_Gi = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_bj_in_Gi = Eigen::Vector3d::Zero();
  bool seen = false;        // a LiDAR observation of j in this scan
  int active_observations = 0;   // fused in this scan
  int passive_observations = 0;  // fused in this scan
};

/// How a teammate was identified.
struct IdentificationEvent {
  int drone_id = -1;
  int64_t stamp_ns = 0;       // own clock
  std::string method;         // "trajectory_match", "teammate_match" (it identified me) or
                              // "graph" (through teammate via_drone_id's own match)
  int via_drone_id = -1;      // "graph": the teammate whose T_Gj_Gk was composed
  double mean_residual_m = 0.0;
  GlobalExtrinsic initial_T_Gi_Gj;
};

struct DroneOutput {
  lio::ScanOutput ego;
  std::vector<TeammateEstimate> teammates;  // every teammate in the state
  std::vector<IdentificationEvent> identifications;  // in this scan
  std::vector<int> removed_teammates;                // left the state in this scan
  int active_observations = 0;    // fused
  int passive_observations = 0;   // fused
  int gravity_alignments = 0;     // teammates' gravity fused
  int rejected_observations = 0;  // gated out or unusable (no recent message)
  bool extrinsics_frozen = false; // degeneracy policy applied
  int num_detector_points = 0;    // full-resolution points given to the detector
};

struct DroneEstimatorCounters {
  int64_t messages_received = 0;
  int64_t messages_ignored = 0;   // own, unknown type, non-finite, stale, or a TimeSync for another drone
  int64_t teammate_restarts = 0;  // session_start changed
  int64_t messages_unsynchronized = 0;  // states of a teammate whose clock offset is not known yet
  int64_t identifications = 0;
  int64_t teammates_removed = 0;
  int64_t active_fused = 0;
  int64_t passive_fused = 0;
  int64_t passive_repeated = 0;     // of passive_fused: sent again after the first message (lost)
  int64_t repeats_duplicate = 0;    // observations of this drone received twice: used once
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
  int64_t observations_unsent = 0;
};

/// One line for the tools' summaries: "broadcast: N B states, ... B
/// extrinsics" (the sent_* counters and observations_unsent), starting with
/// `indent`, ending with a newline.
std::string FormatBroadcastCounters(const DroneEstimatorCounters& c, const std::string& indent);

class DroneEstimator : public lio::ScanStageHooks {
 public:
  static Status Create(int self_id, const DroneEstimatorOptions& options, const LidarOptions& lidar,
                       std::unique_ptr<DroneEstimator>* estimator);
  ~DroneEstimator() override;

  Status AddImu(const ImuSample& sample);
  Status AddScan(const LidarScan& scan);
  /// A message from the network (arrival time in this drone's clock). Bad
  /// or own messages are counted and ignored (Ok).
  Status AddMessage(const net::ReceivedMessage& message);
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
  const lio::Odometry& odometry() const { return *odometry_; }
  const teammate::TeammateDetector& detector() const { return *detector_; }
  const DroneEstimatorCounters& counters() const { return counters_; }
  const DroneEstimatorOptions& options() const { return options_; }

  // lio::ScanStageHooks
  Status OnFrontEnd(const lio::FrontEndScan& scan, SwarmState* x, Eigen::MatrixXd* P,
                    lio::UpdateRequest* request) override;
  void OnScanDone(const lio::ScanOutput& output, const SwarmState& x,
                  const Eigen::MatrixXd& P) override;

 private:
  struct Impl;
  DroneEstimator(int self_id, const DroneEstimatorOptions& options, const LidarOptions& lidar);

  // The raw points the detector needs: tape returns and points near the
  // trackers of the last scan (predicted to t_k).
  void SelectDetectorPoints(const LidarScan& raw, int64_t t_k, const SwarmState& x,
                            const Eigen::Matrix3d& R_imu_lidar, LidarScan* selected) const;

  // Identification through teammates (docs/swarm.md): adds every k that a
  // first-hand teammate j identified and this drone has not.
  void AddTeammatesThroughTeammates(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P);

  // Whether a teammate's message stamped `sender_stamp_ns` (its clock) was
  // made after this drone's session began (by max_message_age_s): false
  // before the odometry initialized or the sender's clock offset is known.
  bool MadeInThisSession(int sender_id, int64_t sender_stamp_ns) const;
  // Whether a sender's message (its clock) about teammate k is from k's
  // current session (k restarted: not before this drone heard the new
  // session + max_message_age_s); true when k never restarted.
  bool MadeInSessionOf(int teammate_id, int sender_id, int64_t sender_stamp_ns) const;

  // The scan's broadcast (drone_estimator_broadcast.cc): the own state with
  // what fits the byte budget of echoes, observations and repeats, and the
  // own T_Gi_Gj estimates when new or due.
  void Broadcast(const lio::ScanOutput& output, const SwarmState& x, const Eigen::MatrixXd& P);
  // Keeps the observations of the state message `m` that the next message
  // repeats (SwarmOptions::repeat_observations), moved into G_i.
  void RememberForRepeat(const net::EgoStateMessage& m, const SwarmState& x,
                         const Eigen::MatrixXd& P);

  int self_id_;
  DroneEstimatorOptions options_;
  LidarOptions lidar_;
  std::unique_ptr<lio::Odometry> odometry_;
  std::unique_ptr<teammate::TeammateDetector> detector_;
  std::unique_ptr<Impl> impl_;
  DroneEstimatorCounters counters_;
  bool fusion_enabled_ = true;
};

}  // namespace swarmlio::swarm
