// Flights must clear the scene: a drone whose planned flight passes through a
// solid is physically impossible, and its simulated LiDAR would see the
// solid's faces from inside (exploration.yaml did so until session 14). The
// body origin is sampled every `step_s` (6 cm at 3 m/s for the default) and
// tested against every closed primitive (boxes, cylinders; rectangles and
// triangles are surfaces). The drone's own size is not modelled: keep about
// 0.2 m of clearance.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "swarmlio/sim/primitives.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {

/// The first sample at which a drone's body origin is inside a solid.
struct FlightThroughSolid {
  size_t drone = 0;                                     // index into the drones
  double t_s = 0.0;                                     // trajectory time [s]
  Eigen::Vector3d body_in_W = Eigen::Vector3d::Zero();  // [m]
  Aabb solid_bounds;
  PrimitiveType solid_type = PrimitiveType::kBox;

  /// "the flight of 'uav1' passes through a box spanning [25, 30, 0] to
  /// [35, 40, 4] m at t = 60.88 s (body at [25.02, 37.69, 2.85] m): add a
  /// waypoint around it".
  std::string Describe(const std::string& drone_name) const;
};

/// Samples every drone's trajectory on [0, duration_s] every `step_s`; the
/// first collision in drone order, or nullopt when every flight is clear.
std::optional<FlightThroughSolid> FindFlightThroughSolid(const std::vector<Primitive>& solids,
                                                         const std::vector<DroneConfig>& drones,
                                                         double duration_s,
                                                         double step_s = 0.02);

}  // namespace swarmlio::sim
