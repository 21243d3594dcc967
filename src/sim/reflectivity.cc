#include "swarmlio/sim/reflectivity.h"

#include <algorithm>
#include <cmath>

namespace swarmlio::sim {
namespace {

// An integer uniform in [intensity_min, intensity_max] (one draw of `rng`).
double ConstantIntensity(const Material& material, std::mt19937_64* rng) {
  const double lo = std::ceil(material.intensity_min);
  const double hi = std::floor(material.intensity_max);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double value = std::floor(lo + (hi - lo + 1.0) * uniform(*rng));
  return std::clamp(value, lo, hi);
}

}  // namespace

double Reflectivity(const ReflectivityOptions& options, const Material& material, double range_m,
                    double cos_incidence, std::mt19937_64* rng) {
  if (material.type == SurfaceType::kConstantIntensity) return ConstantIntensity(material, rng);
  std::normal_distribution<double> normal;
  const double c = std::clamp(cos_incidence, 0.0, 1.0);
  const double fraction = std::clamp(material.reflectivity_percent, 0.0, 100.0) / 100.0;
  if (material.type == SurfaceType::kRetroReflective) {
    // The default band [151, 255] spans 104, the values of the original model.
    const double lo = material.intensity_min;
    const double hi = material.intensity_max;
    const double excess = (hi - lo) * fraction * std::exp(-range_m / options.retro_range_scale_m) *
                          std::pow(c, options.retro_incidence_exponent);
    const double value = lo + excess + options.retro_noise_sigma * normal(*rng);
    return std::round(std::clamp(value, lo, hi));
  }
  const double falloff_ratio = range_m / options.diffuse_range_falloff_m;
  const double value = 150.0 * fraction * c / (1.0 + falloff_ratio * falloff_ratio) +
                       options.diffuse_noise_sigma * normal(*rng);
  return std::round(std::clamp(value, 0.0, 150.0));
}

}  // namespace swarmlio::sim
