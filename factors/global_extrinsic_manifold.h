// GlobalExtrinsicManifold: the parameter block of one teammate's global
// extrinsic T_Gi_Gj,
//   SO(3) x R^3,  ambient 7 = [q_Gi_Gj (x y z w) | p_Gj_in_Gi],
//   tangent 6 = [dtheta | dp]  (ErrorStateLayout teammate-block order),
// with [R; p] (+) [r; d] = [R Exp(r); p + d] (right perturbation, as the paper).
// GlobalExtrinsic::ToParameters / FromParameters convert to and from this block.
#pragma once

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>

#include "factors/so3_manifold.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

using GlobalExtrinsicManifold = ceres::ProductManifold<SO3Manifold, ceres::EuclideanManifold<3>>;

static_assert(GlobalExtrinsic::kAmbientSize == SO3Manifold::kAmbientSize + 3);
static_assert(GlobalExtrinsic::kTangentSize == SO3Manifold::kTangentSize + 3);

}  // namespace swarmlio
