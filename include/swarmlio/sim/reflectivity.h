// Reflectivity on the Livox 0-255 scale.
//
//  diffuse (albedo rho %):  150 * rho/100 * cos(incidence) / (1 + (r / r_d)^2) + noise, in [0, 150]
//  retro (gain g %):        151 + 104 * g/100 * exp(-r / r_retro) * cos(incidence)^k + noise,
//                           in [151, 255]
// so tape stays above any diffuse target but falls with range and incidence
// and crosses a 200-240 detection threshold at a few to ~20 m.
#pragma once

#include <random>

#include "swarmlio/sim/lidar_options.h"
#include "swarmlio/sim/primitives.h"

namespace swarmlio::sim {

/// `cos_incidence` = |cos| of the angle between ray and surface normal.
double Reflectivity(const ReflectivityOptions& options, const Material& material, double range_m,
                    double cos_incidence, std::mt19937_64* rng);

}  // namespace swarmlio::sim
