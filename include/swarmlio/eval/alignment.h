// Umeyama alignment of an estimated trajectory onto its reference, as evo's
// -a (SE(3)) and -as (Sim(3)) do: (s, R, t) minimises
// sum |p_ref_i - (s R p_est_i + t)|^2 over the associated positions
// (math/umeyama.h), then every estimated pose becomes
//   R_G_b' = R R_G_b,   p_b_in_G' = s R p_b_in_G + t.
#pragma once

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/trajectory.h"
#include "swarmlio/math/umeyama.h"

namespace swarmlio::eval {

enum class Alignment { kNone, kSe3, kSim3 };

/// "none", "se3", "sim3" (false for anything else).
bool AlignmentFromString(const std::string& text, Alignment* alignment);
const char* AlignmentName(Alignment alignment);

/// Aligns `estimate` onto `reference` (same number of poses, pair k =
/// (reference k, estimate k)). kNone copies the estimate and reports the
/// identity. Errors: different sizes, fewer than 3 poses, degenerate positions.
Status AlignTrajectory(const Trajectory& reference,
                       const Trajectory& estimate,
                       Alignment alignment,
                       Trajectory* aligned_estimate,
                       UmeyamaResult* transform);

/// Applies a similarity (scale, R_dst_src, t_dst_src) to every pose.
Trajectory TransformTrajectory(const Trajectory& trajectory, const UmeyamaResult& transform);

}  // namespace swarmlio::eval
