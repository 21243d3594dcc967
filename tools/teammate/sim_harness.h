// Simulation harness for the teammate detector (docs/teammate.md,
// "Acceptance"): turns one simulated drone's scans into detector inputs,
// makes the teammates' broadcasts, and measures the detector's outputs
// against the truth.
//
// Ego poses (the observer's and the teammates' broadcast states) come from
// the TRUE trajectories by default (the issue prescribes true ego poses), or
// from each drone's lio::Odometry estimate (EstimateEgoTrajectories) when
// HarnessOptions::ego_estimates is set. Input conventions:
//  - Every point is moved from the LiDAR frame to the body frame at the scan
//    END with the ego pose at the point's own time (1 ms pose samples), so
//    the scan is motion-compensated (exactly with true poses); the scan stamp
//    is the end of the frame (record time) and T_Gi_bi is the ego pose then.
//    True poses use the true LiDAR-IMU extrinsic, estimated poses the one the
//    odometry was given (with the scenario's calibration error).
//  - Teammate j broadcasts its ego state in G_j at each of its scan ends
//    (its LiDAR rate), a seeded fraction of the messages is lost, and the rest
//    arrive `latency_s` later. Stamps are converted into the observer's clock
//    with the simulator's StampNs (a perfectly synchronised clock; the real
//    system corrects the offset with its NTP-style exchange).
//  - Without an ego pose (estimates: before the odometry's first output) a
//    scan is skipped and counted, a broadcast is not sent.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/sim/simulator.h"
#include "swarmlio/teammate/scan_types.h"
#include "swarmlio/teammate/teammate_detector.h"

namespace swarmlio::teammate::harness {

/// One state of a drone's estimated ego trajectory, in its own global frame.
struct EgoEstimate {
  int64_t stamp_ns = 0;  // the drone's clock
  Eigen::Quaterniond q_G_b = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_b_in_G = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_b_in_G = Eigen::Vector3d::Zero();
};

/// A drone's ego trajectory as its lio::Odometry estimated it: the output
/// state of every scan (at the scan end, the drone's clock) in the drone's
/// G (the odometry's global frame is the simulator's G_j = T_W_G(j): the IMU
/// frame at t = 0, where the drone stands still).
struct EstimatedTrajectory {
  /// The calibration the odometry was given (sim::GivenCalibration: the
  /// truth with the scenario's calibration error); the harness moves the
  /// points into the body with the same extrinsic.
  sim::SensorCalibration calibration;
  std::vector<EgoEstimate> states;  // strictly increasing stamps

  /// The state at `stamp_ns`: between two outputs position and velocity are
  /// interpolated linearly and the attitude by slerp; up to
  /// kMaxExtrapolationNs after the last output, extrapolated with its
  /// velocity (the odometry stamps a scan at its last point, ~5 us before
  /// the frame's end on indoor_3uav). False outside that (before the first
  /// output).
  bool StateAt(int64_t stamp_ns, EgoEstimate* state) const;

  static constexpr int64_t kMaxExtrapolationNs = 1000000;  // 1 ms
};

/// Runs lio::Odometry (driver::DefaultOdometryOptions, the given
/// calibration) over every drone's simulated data (Simulator::Run, drones in
/// parallel) and keeps its per-scan outputs; (*trajectories)[j] is drone j's.
Status EstimateEgoTrajectories(const sim::Simulator& sim,
                               std::vector<EstimatedTrajectory>* trajectories);
/// The largest position [m] and attitude [deg] errors of drone `drone`'s
/// estimated states against its true trajectory in G_j.
void EstimateErrors(const sim::Simulator& sim, int drone, const EstimatedTrajectory& estimate,
                    double* max_position_error_m, double* max_rotation_error_deg);

struct HarnessOptions {
  double drop_probability = 0.1;  // fraction of lost broadcast messages
  double latency_s = 0.02;        // delivery delay of a broadcast [s]
  uint64_t seed = 7;              // message-loss seed
  double pose_sample_dt_s = 0.001;  // ego-pose sampling for motion compensation [s]
  /// The ego poses of every drone (observer and teammates), by drone index;
  /// nullptr: the true trajectories. Not owned; must outlive the run.
  const std::vector<EstimatedTrajectory>* ego_estimates = nullptr;
};

/// One scan ready for TeammateDetector::ProcessScan.
struct PreparedScan {
  int observer = 0;
  int64_t stamp_ns = 0;   // observer clock, scan end
  double t_true_s = 0.0;  // true time of the scan end
  Eigen::Isometry3d T_Gi_bi = Eigen::Isometry3d::Identity();  // ego pose at the scan end
  std::vector<ScanPoint> points;
  std::vector<TeammateOdometry> odometry;  // broadcasts delivered since the previous scan
};

using ScanCallback = std::function<Status(const PreparedScan&)>;

/// Simulates drone `observer` (Simulator::RunDrone) and calls `callback` for
/// every scan with an ego pose in time order; the others are counted in
/// `scans_without_pose` (optional).
Status SimulateObserver(const sim::Simulator& sim, int observer, const HarnessOptions& options,
                        const ScanCallback& callback, int* scans_without_pose = nullptr);

/// True T_Gi_Gj = T_W_Gi^-1 T_W_Gj.
Eigen::Isometry3d TrueGlobalExtrinsic(const sim::Simulator& sim, int i, int j);
/// True ^{b_i}p_{b_j} at true time t.
Eigen::Vector3d TruePositionInBody(const sim::Simulator& sim, int i, int j, double t);
/// First true time at which drone j's horizontal speed exceeds 0.05 m/s: the
/// start of the excitation flight (the plans hover, take off vertically, then excite).
double ExcitationStartTime(const sim::Simulator& sim, int j);

// ---------------------------------------------------------------------------
// Evaluation of one observer.

/// How well one teammate is visible to the observer over the run (from the
/// truth: scan points within 0.3 m of the teammate's true position).
struct VisibilityRecord {
  int scans_with_points = 0;      // scans with >= 3 points on the teammate
  int scans_with_tape = 0;        // scans with >= 3 of them above the reflectivity threshold
  double first_tape_s = -1.0;     // first such scan after the excitation start (-1: never)
};

struct IdentificationRecord {
  int observer = 0;
  int teammate = 0;
  double t_true_s = 0.0;
  double since_excitation_s = 0.0;  // t - the later excitation start of the pair
  double since_visible_s = 0.0;     // t - max(that, first scan with tape on the teammate)
  double translation_error_m = 0.0;
  double rotation_error_deg = 0.0;
  double yaw_error_deg = 0.0;  // the rotation error's component about G_i's z axis
  double mean_residual_m = 0.0;
  double second_best_residual_m = 0.0;
  int num_pairs = 0;
  bool correct = false;  // the tracker was on drone `teammate` when identified
};

struct ObservationRecord {
  int observer = 0;
  int teammate = 0;
  double t_true_s = 0.0;
  double range_m = 0.0;
  double error_m = 0.0;
  double along_error_m = 0.0;     // along the line of sight (+: observation beyond the truth)
  double vertical_error_m = 0.0;  // along the observer's body z
};

struct ObserverReport {
  int observer = 0;
  int scans = 0;               // scans given to the detector
  int scans_without_pose = 0;  // skipped: no ego pose (before the estimate's first output)
  int64_t points = 0;
  std::vector<IdentificationRecord> identifications;
  std::vector<ObservationRecord> observations;
  int temporary_on_teammates = 0;   // temporary trackers started on a drone
  int temporary_elsewhere = 0;      // ... on anything else (decoys, clutter)
  int wrong_observations = 0;       // observations farther than 0.3 m from the drone they name
  std::vector<VisibilityRecord> visibility;  // by teammate index
  std::vector<double> process_ms;   // ProcessScan wall time per scan
  std::vector<int> scan_sizes;
};

/// Called after every scan with the detector's output (diagnostics).
using ResultCallback = std::function<void(const PreparedScan&, const ScanResult&)>;

/// Runs the detector on drone `observer` for the whole simulation.
Status EvaluateObserver(const sim::Simulator& sim, int observer,
                        const TeammateDetectorOptions& detector_options,
                        const HarnessOptions& options, ObserverReport* report,
                        const ResultCallback& on_result = nullptr);

}  // namespace swarmlio::teammate::harness
