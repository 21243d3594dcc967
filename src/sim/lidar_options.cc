#include "swarmlio/sim/lidar_options.h"

namespace swarmlio::sim {

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
