#include "swarmlio/sim/flight_clearance.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace swarmlio::sim {

std::string FlightThroughSolid::Describe(const std::string& drone_name) const {
  std::ostringstream os;
  os.precision(3);
  const Aabb& b = solid_bounds;
  os << "the flight of '" << drone_name << "' passes through a "
     << (solid_type == PrimitiveType::kCylinder ? "cylinder" : "box") << " spanning ["
     << b.min.x() << ", " << b.min.y() << ", " << b.min.z() << "] to [" << b.max.x() << ", "
     << b.max.y() << ", " << b.max.z() << "] m";
  os.precision(4);
  os << " at t = " << t_s << " s (body at [" << body_in_W.x() << ", " << body_in_W.y() << ", "
     << body_in_W.z() << "] m): add a waypoint around it";
  return os.str();
}

std::optional<FlightThroughSolid> FindFlightThroughSolid(const std::vector<Primitive>& solids,
                                                         const std::vector<DroneConfig>& drones,
                                                         double duration_s, double step_s) {
  const int steps = static_cast<int>(std::ceil(duration_s / step_s));
  for (size_t i = 0; i < drones.size(); ++i) {
    for (int k = 0; k <= steps; ++k) {
      const double t = std::min(duration_s, k * step_s);
      const Eigen::Vector3d p = drones[i].trajectory.PositionAt(t);
      for (const Primitive& solid : solids) {
        const Aabb& b = solid.bounds();
        if ((p.array() <= b.min.array()).any() || (p.array() >= b.max.array()).any()) continue;
        if (!solid.Contains(p)) continue;
        return FlightThroughSolid{i, t, p, b, solid.type()};
      }
    }
  }
  return std::nullopt;
}

}  // namespace swarmlio::sim
