// Time association of a reference and an estimated trajectory, as evo's
// sync.associate_trajectories does it:
//   - the shorter trajectory's stamps (the estimate's when both have the same
//     number of poses) are each matched to the nearest stamp of the longer
//     one; the first of equally near stamps wins;
//   - a pair is kept when |dt| <= max_time_diff_s; a pose of the longer
//     trajectory may be used by several pairs;
//   - time_offset_s is added to the estimate's stamps before matching.
// If either trajectory has no stamps (KITTI), poses are paired by index and
// both must have the same number of poses.
#pragma once

#include <cstddef>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/trajectory.h"

namespace swarmlio::eval {

/// Pairing of the poses of two trajectories by stamp (AssociateTrajectories).
struct TrajectoryAssociationOptions {
  double max_time_diff_s = 0.01;  // evo's --t_max_diff default [s]
  double time_offset_s = 0.0;     // added to the estimate's stamps [s]
};

struct AssociatedTrajectories {
  /// Matched poses, pair k = (reference[k], estimate[k]), in the order of the
  /// shorter trajectory.
  Trajectory reference;
  Trajectory estimate;
  /// Indices of the pairs in the input trajectories.
  std::vector<size_t> reference_ids;
  std::vector<size_t> estimate_ids;
  /// Poses of the shorter trajectory (the most pairs there could be).
  size_t max_pairs = 0;
};

/// Errors: an empty trajectory, a negative or non-finite tolerance, different
/// sizes without stamps, no pair within the tolerance.
Status AssociateTrajectories(const Trajectory& reference,
                             const Trajectory& estimate,
                             const TrajectoryAssociationOptions& options,
                             AssociatedTrajectories* result);

}  // namespace swarmlio::eval
