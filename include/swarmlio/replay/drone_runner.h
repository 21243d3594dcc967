// DroneRunner: one drone of an offline replay. It owns the drone's bag
// reader and its driver::DroneDriver (the component); the replay loop asks
// for the stamp of its next record and lets it consume that record (so N
// drones interleave in stamp order).
// It keeps the component's per-scan outputs, trimmed by KeptOutput (about
// 3 kB a scan, most of it the ego covariance), and the ground truth found in
// the bag.
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

/// The output kept of each scan: the component's output without its large
/// members (the registered scan, the error strings, the identifications,
/// which identifications() keeps). See docs/architecture.md "The drivers'
/// one loop".
swarm::DroneOutput KeptOutput(swarm::DroneOutput output);

/// The updated scans' poses with their position covariances (the estimate
/// eval::EvaluateConsistency and eval::CheckGroundTruthFrame take).
eval::CovariantTrajectory UpdatedEstimate(const std::vector<lio::ScanOutput>& scans);
eval::CovariantTrajectory UpdatedEstimate(const std::vector<swarm::DroneOutput>& scans);

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
  /// The outputs of the processed scans, trimmed by KeptOutput.
  const std::vector<swarm::DroneOutput>& scans() const { return scans_; }
  const std::vector<PoseStamped>& bag_ground_truth() const { return ground_truth_; }
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
  std::vector<swarm::DroneOutput> scans_;
  std::vector<net::SwarmMessage> outbox_;  // produced, not taken yet
  std::vector<swarm::IdentificationEvent> identifications_;
  std::vector<PoseStamped> ground_truth_;
};

}  // namespace swarmlio::replay
