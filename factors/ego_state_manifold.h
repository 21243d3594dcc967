// EgoStateManifold: the ego parameter block of one drone,
//   SO(3) x R^15,  ambient 19 = [q_G_b (x y z w) | p_b_in_G | v_b_in_G | b_g | b_a | g_in_G],
//   tangent 18 = [dtheta | dp | dv | db_g | db_a | dg]  (ErrorStateLayout order),
// with the paper's boxplus: [R; a] (+) [r; b] = [R Exp(r); a + b].
// EgoState::ToParameters / FromParameters convert to and from this block.
#pragma once

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>

#include "factors/so3_manifold.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

using EgoStateManifold = ceres::ProductManifold<SO3Manifold, ceres::EuclideanManifold<15>>;

static_assert(EgoState::kAmbientSize == SO3Manifold::kAmbientSize + 15);
static_assert(EgoState::kTangentSize == SO3Manifold::kTangentSize + 15);

}  // namespace swarmlio
