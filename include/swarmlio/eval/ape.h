// Absolute pose error (APE), as evo_ape computes it:
//   1. associate the trajectories (association.h);
//   2. align the estimate onto the reference (alignment.h; none by default);
//   3. E_i = Q_i^-1 P_i for every pair (Q reference, P aligned estimate);
//   4. error_i = PoseRelationError(E_i); statistics over all pairs.
// For kTranslation, error_i = |p_est_i - p_ref_i| (= |t(E_i)|).
#pragma once

#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/alignment.h"
#include "swarmlio/eval/association.h"
#include "swarmlio/eval/error_statistics.h"
#include "swarmlio/eval/pose_relation.h"
#include "swarmlio/eval/trajectory.h"
#include "swarmlio/math/umeyama.h"

namespace swarmlio::eval {

struct ApeOptions {
  PoseRelation relation = PoseRelation::kTranslation;
  Alignment alignment = Alignment::kNone;
  TrajectoryAssociationOptions association;
};

struct ApeResult {
  ErrorStatistics statistics;  // statistics.count = number of pairs
  std::vector<double> errors;  // one per pair, in the unit of the relation
  /// The associated poses; `associated.estimate` before alignment.
  AssociatedTrajectories associated;
  /// The associated estimate after alignment (= associated.estimate for kNone).
  Trajectory aligned_estimate;
  /// The alignment applied (identity and scale 1 for kNone).
  UmeyamaResult alignment_transform;
};

Status ComputeApe(const Trajectory& reference,
                  const Trajectory& estimate,
                  const ApeOptions& options,
                  ApeResult* result);

}  // namespace swarmlio::eval
