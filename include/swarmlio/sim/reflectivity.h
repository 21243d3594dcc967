// Reflectivity on the Livox 0-255 scale.
//
//  diffuse (albedo rho %):  150 * rho/100 * cos(incidence) / (1 + (r / r_d)^2) + noise, in [0, 150]
//  retro (gain g %, band [lo, hi], default [151, 255]):
//                           lo + (hi - lo) * g/100 * exp(-r / r_retro) * cos(incidence)^k + noise,
//                           in [lo, hi]
//  constant intensity:      an integer uniform in [lo, hi], whatever r and incidence
// so tape with the default band stays above any diffuse target but falls with
// range and incidence and crosses a 200-240 detection threshold at a few to
// ~20 m; a dim tape's band (e.g. the `dim_tape` airframe, drone_body.h)
// overlaps the bright diffuse surfaces.
#pragma once

#include <random>

#include "swarmlio/sim/lidar_options.h"
#include "swarmlio/sim/primitives.h"

namespace swarmlio::sim {

/// `cos_incidence` = |cos| of the angle between ray and surface normal. Draws
/// from `rng`: one N(0, 1) number (diffuse, retro) or one uniform (constant intensity).
double Reflectivity(const ReflectivityOptions& options, const Material& material, double range_m,
                    double cos_incidence, std::mt19937_64* rng);

}  // namespace swarmlio::sim
