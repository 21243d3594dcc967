// DroneRunner: one drone of an offline replay. It owns the drone's bag
// reader and its driver::DroneDriver (the component); the replay loop asks
// for the stamp of its next record and lets it consume that record (so N
// drones interleave in stamp order).
// It keeps per-scan results (bounded: a few hundred bytes a scan) and the
// ground truth found in the bag.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/driver/drone_driver.h"
#include "swarmlio/driver/manifest.h"
#include "swarmlio/eval/consistency.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/lio/odometry.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/swarm/drone_estimator.h"

namespace swarmlio::replay {

/// One teammate as an observer estimated it at one of its scan ends
/// (compact: kept for every scan of every drone).
struct TeammateRecord {
  int drone_id = -1;  // index of the teammate in the manifest
  GlobalExtrinsic T_Gi_Gj;
  Eigen::Matrix<double, 6, 1> extrinsic_sigma2 = Eigen::Matrix<double, 6, 1>::Zero();  // cov diagonal
  bool have_pose = false;
  Eigen::Quaterniond q_Gi_bj = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_bj_in_Gi = Eigen::Vector3d::Zero();
  bool seen = false;
  int active_observations = 0;
  int passive_observations = 0;
};

/// The per-scan record kept for evaluation and reports.
struct ScanRecord {
  int64_t stamp_ns = 0;  // state time (scan end)
  EgoState state;
  /// Covariance of [dtheta, dp] (rotation, position), ErrorStateLayout order.
  Eigen::Matrix<double, 6, 6> pose_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();
  bool updated = false;
  bool held_by_initialization = false;  // see lio::ScanOutput
  int num_raw_points = 0;
  int num_points = 0;
  int num_correspondences = 0;
  int iterations = 0;
  double min_normal_information = 0.0;  // see lio::ScanOutput
  bool degenerate = false;
  size_t map_size = 0;
  lio::ScanTimings timings;
  std::vector<TeammateRecord> teammates;  // every teammate in the state
  int active_observations = 0;
  int passive_observations = 0;
  int rejected_observations = 0;
  bool extrinsics_frozen = false;
};

/// The record kept of one estimator output.
ScanRecord ToScanRecord(const lio::ScanOutput& output);
ScanRecord ToScanRecord(const swarm::DroneOutput& output);

/// The updated scans' poses with their position covariances (the estimate
/// eval::EvaluateConsistency and eval::CheckGroundTruthFrame take).
eval::CovariantTrajectory UpdatedEstimate(const std::vector<ScanRecord>& scans);

class DroneRunner : private driver::DriverSink {
 public:
  /// Opens the bag and creates the estimator. Errors name the drone.
  /// `drone_id`: the drone's index in the manifest (its swarm id).
  static Status Create(const driver::DroneInput& input, int drone_id, std::unique_ptr<DroneRunner>* runner);

  /// True while the bag has records left (after Prime()).
  bool has_next() const { return has_next_; }
  /// Stamp of the next record (valid when has_next()).
  int64_t next_stamp_ns() const;
  /// Feeds the next record to the estimator and reads the one after it.
  /// Data problems the estimator skips (NaN sample, out-of-order scan) are
  /// counted as warnings, not errors; a bag read error is returned.
  Status Step();
  /// End of the log: processes the scans still waiting for IMU data.
  Status Finish();
  /// A message from the network, arrived by the next record's stamp.
  void Deliver(const net::ReceivedMessage& message);
  /// Moves the messages the estimator produced since the last call.
  void TakeMessages(std::vector<net::SwarmMessage>* messages);
  /// Ablation switch: fuse mutual observations (true) or not.
  void SetFusion(bool fuse);
  /// Re-run of a live drone: the scans with these stamps (the ones the live
  /// run dropped) are left out, so the re-run processes exactly the scans the
  /// live run processed. IMU samples are never left out.
  void SkipScans(std::vector<int64_t> scan_stamps_ns);
  /// Scans left out by SkipScans so far.
  int64_t skipped_scans() const { return skipped_scans_; }
  /// Identifications so far.
  const std::vector<swarm::IdentificationEvent>& identifications() const {
    return identifications_;
  }

  const driver::DroneInput& input() const { return input_; }
  const std::vector<ScanRecord>& scans() const { return scans_; }
  const std::vector<PoseStamped>& bag_ground_truth() const { return ground_truth_; }
  const lio::Odometry& odometry() const { return driver_->estimator().odometry(); }
  const swarm::DroneEstimator& estimator() const { return driver_->estimator(); }
  const io::BagReader& reader() const { return *reader_; }
  const driver::DroneWarnings& warnings() const { return driver_->warnings(); }

 private:
  DroneRunner() = default;
  Status ReadNext();
  // The restart of DroneInput::restart_at_s: a new estimator, the records of
  // the down time skipped, the outputs of the first session dropped.
  Status Restart();
  // driver::DriverSink: the scans kept, the messages held for TakeMessages.
  void OnOutputs(const std::vector<swarm::DroneOutput>& outputs) override;
  void OnMessages(std::vector<net::SwarmMessage>* messages) override;

  driver::DroneInput input_;
  std::unique_ptr<io::BagReader> reader_;
  std::unique_ptr<driver::DroneDriver> driver_;
  io::BagRecord next_;
  bool has_next_ = false;
  int64_t restart_ns_ = -1;  // pending restart: the log stamp (-1: none)
  std::vector<int64_t> skip_scan_stamps_ns_;  // sorted
  int64_t skipped_scans_ = 0;
  std::vector<ScanRecord> scans_;
  std::vector<net::SwarmMessage> outbox_;  // produced, not taken yet
  std::vector<swarm::IdentificationEvent> identifications_;
  std::vector<PoseStamped> ground_truth_;
};

}  // namespace swarmlio::replay
