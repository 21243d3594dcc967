// The state of one swarm::DroneEstimator, shared by its two translation
// units: drone_estimator.cc (inputs, the scan's front end and its
// observation terms) and drone_estimator_messages.cc (messages in, outputs
// and messages out). Internal to src/swarm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <map>
#include <utility>
#include <vector>

#include "dead_reckoning.h"
#include "observation_terms.h"
#include "swarmlio/lio/undistortion.h"
#include "swarmlio/swarm/broadcast_budget.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "teammate_state.h"

namespace swarmlio::swarm {
namespace internal {

inline double Seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// What OnScanDone records, joined with the odometry's output afterwards.
struct SwarmPart {
  std::vector<TeammateEstimate> teammates;
  std::vector<IdentificationEvent> identifications;
  std::vector<int> removed;
  int active = 0;
  int passive = 0;
  int gravity = 0;
  int rejected = 0;
  int skipped_degenerate = 0;
  bool frozen = false;
  int detector_points = 0;
};

}  // namespace internal

struct DroneEstimator::Impl {
  std::map<int, internal::TeammateInfo> teammates;
  std::map<int, internal::PendingMutual> mutual;  // by sender
  int64_t last_extrinsic_broadcast_ns = 0;
  bool broadcast_extrinsics_once = false;
  // What leaves: a byte budget, and the order in which teammates' items
  // share it (broadcast_budget.h).
  BroadcastBudget budget;
  SendRotation observation_rotation;
  SendRotation extrinsic_rotation;
  std::deque<internal::PendingPassive> passive;
  internal::MutualObservationModel model;
  LidarScan selected;  // the raw points handed to the detector
  std::vector<UndistortedPoint> undistorted;
  std::vector<teammate::ScanPoint> points;
  teammate::ScanResult detection;
  double last_detection_stamp_s = 0.0;
  double degenerate_average = 0.0;  // EMA of the own degeneracy flags
  // Own propagated accelerations of the last seconds: their double integral
  // moves a passive observation's ego position from t_k back to t_j together
  // with the state's velocity (dead_reckoning.h, docs/swarm.md section 8).
  internal::DeadReckoningTrack dead_reckoning;
  Eigen::Vector3d last_gyro = Eigen::Vector3d::Zero();
  // The scan in flight (between OnFrontEnd and OnScanDone).
  internal::SwarmPart part;
  std::map<int, std::pair<int, int>> fused_by_teammate;  // active, passive
  std::deque<internal::SwarmPart> parts;
  std::vector<lio::ScanOutput> odometry_outputs;
  std::vector<DroneOutput> outputs;
  std::vector<net::SwarmMessage> messages;
  // This scan's observations to send again with the next state message
  // (SwarmOptions::repeat_observations), in G_i; age_ns unset.
  std::vector<net::PastObservation> repeat;
  int64_t repeat_stamp_ns = 0;
  // Clock synchronisation: the requests to answer when the messages are
  // taken (t3 = send time), and the newest sensor stamp ("now").
  std::unique_ptr<net::ClockSync> clock_sync;
  std::vector<std::pair<net::TimeSyncMessage, int64_t>> sync_requests;  // with arrival
  std::map<int, int64_t> clock_sessions;  // session_start_ns each teammate's clock belongs to
  int64_t now_ns = std::numeric_limits<int64_t>::min();
};

}  // namespace swarmlio::swarm
