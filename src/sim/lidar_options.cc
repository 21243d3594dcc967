#include "swarmlio/sim/lidar_options.h"

namespace swarmlio::sim {

std::string LidarImperfectionOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  const bool has_divergence =
      beam_divergence_horizontal_deg > 0.0 || beam_divergence_vertical_deg > 0.0;
  if (SamplesFootprint() && !has_divergence) {
    return std::string(multi_return ? "multi_return" : "mixed_pixel_probability") +
           ": needs a beam footprint (beam_divergence_horizontal_deg or _vertical_deg > 0)";
  }
  if (incidence_noise && !has_divergence) {
    return "incidence_noise: needs a beam footprint (beam_divergence_horizontal_deg or "
           "_vertical_deg > 0)";
  }
  return {};
}

std::string SimulatedLidarOptions::Validate() const {
  std::string error = sensor.Validate();
  if (error.empty()) error = config::ValidateFields(*this);
  if (error.empty() &&
      static_cast<double>(sensor.points_per_second) < sensor.scan_rate_hz * sensor.num_lines) {
    error = "points_per_second: must be at least scan_rate_hz * num_lines for the simulator";
  }
  return error;
}

}  // namespace swarmlio::sim
