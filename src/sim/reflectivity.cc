#include "swarmlio/sim/reflectivity.h"

#include <algorithm>
#include <cmath>

namespace swarmlio::sim {

double Reflectivity(const ReflectivityOptions& options, const Material& material, double range_m,
                    double cos_incidence, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  const double c = std::clamp(cos_incidence, 0.0, 1.0);
  const double fraction = std::clamp(material.reflectivity_percent, 0.0, 100.0) / 100.0;
  if (material.type == SurfaceType::kRetroReflective) {
    const double excess = 104.0 * fraction * std::exp(-range_m / options.retro_range_scale_m) *
                          std::pow(c, options.retro_incidence_exponent);
    const double value = 151.0 + excess + options.retro_noise_sigma * normal(*rng);
    return std::round(std::clamp(value, 151.0, 255.0));
  }
  const double falloff_ratio = range_m / options.diffuse_range_falloff_m;
  const double value = 150.0 * fraction * c / (1.0 + falloff_ratio * falloff_ratio) +
                       options.diffuse_noise_sigma * normal(*rng);
  return std::round(std::clamp(value, 0.0, 150.0));
}

}  // namespace swarmlio::sim
