// Simulation harness for the teammate detector (docs/teammate.md,
// "Acceptance"): turns one simulated drone's scans into detector inputs
// using TRUE poses, makes the teammates' broadcasts from their true
// trajectories, and measures the detector's outputs against the truth.
//
// Input conventions (the issue prescribes true ego poses):
//  - Every point is moved from the LiDAR frame to the body frame at the scan
//    END with the true trajectory at the point's own time (1 ms pose
//    samples), so the scan is motion-compensated exactly; the scan stamp is
//    the end of the frame (record time) and T_Gi_bi is the true pose then.
//  - Teammate j broadcasts its true state in G_j at each of its scan ends
//    (its LiDAR rate), a seeded fraction of the messages is lost, and the rest
//    arrive `latency_s` later. Stamps are converted into the observer's clock
//    with the simulator's StampNs (a perfectly synchronised clock; the real
//    system corrects the offset with its NTP-style exchange).
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

struct HarnessOptions {
  double drop_probability = 0.1;  // fraction of lost broadcast messages
  double latency_s = 0.02;        // delivery delay of a broadcast [s]
  uint64_t seed = 7;              // message-loss seed
  double pose_sample_dt_s = 0.001;  // true-pose sampling for motion compensation [s]
};

/// One scan ready for TeammateDetector::ProcessScan.
struct PreparedScan {
  int observer = 0;
  double stamp_s = 0.0;   // observer clock, scan end
  double t_true_s = 0.0;  // true time of the scan end
  Eigen::Isometry3d T_Gi_bi = Eigen::Isometry3d::Identity();  // true pose at the scan end
  std::vector<ScanPoint> points;
  std::vector<TeammateOdometry> odometry;  // broadcasts delivered since the previous scan
};

using ScanCallback = std::function<Status(const PreparedScan&)>;

/// Simulates drone `observer` (Simulator::RunDrone) and calls `callback` for
/// every scan in time order.
Status SimulateObserver(const sim::Simulator& sim, int observer, const HarnessOptions& options,
                        const ScanCallback& callback);

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
  int scans = 0;
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
