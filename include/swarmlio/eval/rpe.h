// Relative pose error (RPE), as evo_rpe computes it (consecutive pairs):
//   1. associate the trajectories; optionally align (no alignment by default);
//   2. pick index pairs (i, j) on the associated estimate's poses:
//      frames:  ids 0, d, 2d, ... (while < n), pairs of consecutive ids;
//      metres:  walk the estimate summing |p_k - p_(k-1)|; each time the sum
//               reaches >= d emit the index k and reset the sum to 0 (so the
//               first id is the first index reaching d, not 0); pairs of
//               consecutive ids;
//      all pairs (evo's --all_pairs), instead of consecutive ids:
//        frames: (i, i + d) for every i with i + d < n;
//        metres: for every i, the j > i whose path length from i, L(i, j),
//                is nearest to d (ties: the smaller j), kept when
//                |L(i, j) - d| <= all_pairs_relative_tolerance * d (evo's
//                rel_tol, 0.1): overlapping segments of about d metres, the
//                drift-per-distance figure (mean error / d);
//   3. E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j); error = PoseRelationError(E).
//      With translation_in_world (not in evo): error = |(p_j - p_i) - (q_j - q_i)|,
//      the displacement error in the reference's world frame (after the
//      alignment, SE(3) as a rule). E's translation is the displacement in the
//      start pose's frame, so a constant attitude offset of the estimate (a
//      LiDAR-IMU rotation error carried into the body attitude) adds angle x
//      distance to it; the world form leaves attitude out, and the alignment
//      removes a rotation of the whole trajectory (the map frame's gauge).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/alignment.h"
#include "swarmlio/eval/association.h"
#include "swarmlio/eval/error_statistics.h"
#include "swarmlio/eval/pose_relation.h"
#include "swarmlio/eval/trajectory.h"

namespace swarmlio::eval {

enum class DeltaUnit { kFrames, kMeters };

/// "f" / "frames", "m" / "meters" / "metres" (false for anything else).
bool DeltaUnitFromString(const std::string& text, DeltaUnit* unit);
/// "f" or "m".
const char* DeltaUnitName(DeltaUnit unit);

struct RpeOptions {
  PoseRelation relation = PoseRelation::kTranslation;
  double delta = 1.0;  // a positive integer for frames, > 0 for metres
  DeltaUnit delta_unit = DeltaUnit::kFrames;
  bool all_pairs = false;  // every start pose, not consecutive ids (evo --all_pairs)
  double all_pairs_relative_tolerance = 0.1;  // metres with all_pairs: |L - d| <= this x d
  Alignment alignment = Alignment::kNone;
  bool translation_in_world = false;  // step 3, world form; needs relation kTranslation
  TrajectoryAssociationOptions association;
};

using IdPair = std::pair<size_t, size_t>;

/// The (i, j) index pairs of the rule above on `poses`, consecutive ids.
/// Errors: a bad delta, no pair (the trajectory is shorter than two deltas).
Status RpeIdPairs(const Trajectory& poses,
                  double delta,
                  DeltaUnit unit,
                  std::vector<IdPair>* id_pairs);

/// The same with all pairs (step 2, "all pairs"); `relative_tolerance` in
/// [0, 1) applies to metres. Errors: a bad delta or tolerance, no pair.
Status RpeAllIdPairs(const Trajectory& poses,
                     double delta,
                     DeltaUnit unit,
                     double relative_tolerance,
                     std::vector<IdPair>* id_pairs);

struct RpeResult {
  ErrorStatistics statistics;    // statistics.count = number of pairs
  std::vector<double> errors;    // one per pair
  std::vector<IdPair> id_pairs;  // indices into the associated trajectories
  AssociatedTrajectories associated;
  Trajectory aligned_estimate;  // = associated.estimate for kNone
};

Status ComputeRpe(const Trajectory& reference,
                  const Trajectory& estimate,
                  const RpeOptions& options,
                  RpeResult* result);

}  // namespace swarmlio::eval
