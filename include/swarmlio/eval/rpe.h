// Relative pose error (RPE), as evo_rpe computes it (consecutive pairs):
//   1. associate the trajectories; optionally align (no alignment by default);
//   2. pick index pairs (i, j) on the associated estimate's poses:
//      frames:  ids 0, d, 2d, ... (while < n), pairs of consecutive ids;
//      metres:  walk the estimate summing |p_k - p_(k-1)|; each time the sum
//               reaches >= d emit the index k and reset the sum to 0 (so the
//               first id is the first index reaching d, not 0); pairs of
//               consecutive ids;
//   3. E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j); error = PoseRelationError(E).
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
  Alignment alignment = Alignment::kNone;
  AssociationOptions association;
};

using IdPair = std::pair<size_t, size_t>;

/// The (i, j) index pairs of the rule above on `poses`. Errors: a bad delta,
/// no pair (the trajectory is shorter than two deltas).
Status RpeIdPairs(const Trajectory& poses,
                  double delta,
                  DeltaUnit unit,
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
