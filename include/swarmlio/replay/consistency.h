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
#pragma once

#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/replay/drone_runner.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::replay {

struct ConsistencyStats {
  int num_poses = 0;                // scans with ground truth
  double position_rmse_m = 0.0;     // no alignment
  double position_max_m = 0.0;
  double mean_position_nees = 0.0;  // expected 3
  double expected_position_nees = 3.0;
  double rotation_rmse_deg = 0.0;   // |Log(R_true^T R_est)|
};

/// Ground-truth pose at `stamp_ns` interpolated from `gt` (sorted by stamp).
/// False when `stamp_ns` is outside `gt` or the bracketing poses are more
/// than max_gap_ns apart.
bool InterpolatePose(const std::vector<PoseStamped>& gt, int64_t stamp_ns, int64_t max_gap_ns,
                     PoseStamped* pose);

/// Statistics over the updated scans of `scans` with ground truth.
/// FailedPrecondition when no scan overlaps the ground truth.
Status EvaluateConsistency(const std::vector<ScanRecord>& scans,
                           const std::vector<PoseStamped>& gt, double max_gt_gap_s,
                           ConsistencyStats* stats);

}  // namespace swarmlio::replay
