// Position accuracy and filter consistency of a run against ground truth in
// the SAME frame (no alignment): the estimator's G is the IMU frame at its
// static initialization, which for a drone that is still during it equals
// the ground truth's frame (the IMU frame at the start of the log).
//
// For each scan state at time t with ground truth interpolated at t (linear
// in position, slerp in rotation, between poses at most max_gt_gap_s apart):
//   e_p = p_est - p_true,  NEES_p = e_p^T P_pp^-1 e_p  (expected value 3)
// The average NEES is reported with its expected value; a consistent filter
// has mean NEES close to 3 (the acceptance band: [0.3, 3] x 3).
// Ground truth in another frame (mocap, simulator world) must first be
// detected (CheckGroundTruthFrame) and aligned; its NEES is meaningless.
//
// The estimate's frame is realized only up to a gauge: the first scan anchors
// the map through the LiDAR-IMU calibration, so a calibration rotation error
// dR rotates every later position about the start (|p| dR: 0.30 m at 40 m for
// 0.44 deg in corridor seed 103). The filter's covariance is relative to its
// map (the map is not in the state); the odometry adds the calibration's
// share to the position covariance in G (lio/calibration_gauge.h), which the
// NEES in G uses. The gauge-aligned NEES (a diagnostic) instead first
// rotates the ground truth about the first pose onto the estimate (the
// rotation that best fits the displacements from the first pose: AlignUmeyama
// without translation), as OpenVINS' ov_eval aligns the ground truth to the
// estimate before its NEES (ResultTrajectory::calculate_nees), with the
// covariances relative to the map. Both are reported; the acceptance band
// uses the NEES in G.
//
// The estimate is an eval::Trajectory of the updated scans' poses with the
// covariance of each position; the ground truth an eval::Trajectory. Both are
// compared at the estimate's stamps in integer nanoseconds (the stamps
// round-trip exactly through the trajectories' seconds for stamps below
// 2e6 s; above, to within 1 us), the ground truth interpolated from
// its quaternions (linear in position, slerp in rotation).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/eval/trajectory.h"

namespace swarmlio::eval {

/// Frame of a drone's ground truth (manifest key `ground_truth_frame`).
///   kAuto:  G when the ground truth at the estimate's first stamp matches the
///           estimate's first pose (within tolerance), else another frame
///   kG:     the estimator's G (the IMU frame at the static start), declared
///   kOther: another frame (mocap, simulator world), declared
enum class GroundTruthFrame { kAuto, kG, kOther };

/// An estimate with the covariance of each position p_b_in_G [m^2], one per
/// pose (a filter's or smoother's output; the updated scans only): against
/// the true G (with the map's own uncertainty, lio::ScanOutput::
/// position_covariance_in_G), and optionally relative to the estimator's own
/// map (the filter's; empty = the same), which the gauge-aligned NEES uses.
struct CovariantTrajectory {
  Trajectory poses;
  std::vector<Eigen::Matrix3d> position_covariances;
  std::vector<Eigen::Matrix3d> map_position_covariances;
};

struct ConsistencyStats {
  int num_poses = 0;             // scans with ground truth
  double position_rmse_m = 0.0;  // no alignment
  double position_max_m = 0.0;
  double mean_position_nees = 0.0;  // in G, no alignment; expected 3
  /// After rotating the ground truth about the first pose onto the estimate
  /// (the gauge); NaN when the displacements do not fix a rotation (a hover
  /// or a line: second singular value of their scatter about the first pose
  /// below 0.01 m^2) or fewer than 3 poses.
  double mean_position_nees_aligned = 0.0;
  double gauge_rotation_deg = 0.0;  // the rotation of that alignment
  double expected_position_nees = 3.0;
  double rotation_rmse_deg = 0.0;  // |Log(R_true^T R_est)|
};

/// Whether a drone's ground truth is in the estimator's frame G. G is the
/// IMU frame at the static initialization, so ground truth in G starts where
/// the estimate starts; a mocap or simulator world does not.
struct FrameCheckOptions {
  double max_position_offset_m = 0.1;    // first-pose position difference still "same frame" [m]
  double max_rotation_offset_deg = 3.0;  // first-pose rotation difference still "same frame" [deg]
  double max_gt_gap_s = 0.05;            // interpolation gap of the ground truth [s]
};

struct FrameCheck {
  bool compared = false;             // a ground-truth pose was found at an estimate stamp
  int64_t stamp_ns = 0;              // the first estimate stamp with ground truth
  double position_offset_m = 0.0;    // |p_true - p_est| there
  double rotation_offset_deg = 0.0;  // |Log(R_true^T R_est)| there
  bool declared = false;             // the manifest said G or other (no detection)
  bool same_frame = false;  // frames known to agree: NEES and unaligned errors are meaningful
  /// One line, e.g. "ground truth in G (first pose within 0.004 m, 0.1 deg)" or
  /// "ground truth in another frame: aligned by first pose and SE(3) (first
  /// pose 3.2 m, 88.5 deg from the estimate's)".
  std::string Summary() const;
};

/// Compares the ground truth with the estimate at the first pose that the
/// ground truth covers; `declared` (manifest ground_truth_frame) decides
/// when not kAuto. FailedPrecondition when no scan overlaps the ground truth.
Status CheckGroundTruthFrame(const Trajectory& estimate,
                             const Trajectory& gt,
                             GroundTruthFrame declared,
                             const FrameCheckOptions& options,
                             FrameCheck* check);

/// The ground truth moved into G by its first pose: every pose is premultiplied
/// by T_G_W = T_est(t0) T_true(t0)^-1, t0 = check.stamp_ns (needs
/// check.compared). The estimate's drift since t0 stays in the errors.
Status AlignGroundTruthByFirstPose(const Trajectory& estimate,
                                   const Trajectory& gt,
                                   const FrameCheck& check,
                                   double max_gt_gap_s,
                                   Trajectory* aligned);

/// Statistics over the poses of `estimate` with ground truth.
/// FailedPrecondition when no pose overlaps the ground truth.
Status EvaluateConsistency(const CovariantTrajectory& estimate,
                           const Trajectory& gt,
                           double max_gt_gap_s,
                           ConsistencyStats* stats);

}  // namespace swarmlio::eval

namespace swarmlio::config {

template <>
struct EnumTraits<eval::GroundTruthFrame> {
  static constexpr std::array<std::pair<eval::GroundTruthFrame, const char*>, 3> kNames{{
      {eval::GroundTruthFrame::kAuto, "auto"},
      {eval::GroundTruthFrame::kG, "G"},
      {eval::GroundTruthFrame::kOther, "other"},
  }};
};

}  // namespace swarmlio::config
