#include "swarmlio/sim/drone_body.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/math/so3.h"

namespace swarmlio::sim {

std::string DroneBodyOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (error.empty() && tape_height_m > core_size_m.z()) {
    error = "tape_height_m: must not exceed core_size_m[2]";
  }
  return error;
}

std::vector<Primitive> MakeDroneBody(const DroneBodyOptions& o) {
  std::vector<Primitive> parts;
  const Material body = Material::Diffuse(o.body_albedo_percent);
  const Eigen::Vector3d half_core = 0.5 * o.core_size_m;
  parts.push_back(Primitive::AxisAlignedBox(-half_core, half_core, body));
  if (o.tape_height_m > 0.0) {
    const Eigen::Vector3d half_tape(half_core.x() + 0.002, half_core.y() + 0.002,
                                    0.5 * o.tape_height_m);
    parts.push_back(Primitive::AxisAlignedBox(-half_tape, half_tape,
                                              Material::RetroReflective(o.tape_gain_percent)));
  }
  const Eigen::Vector3d half_arm(0.5 * o.arm_span_m, 0.015, 0.012);
  for (double angle : {M_PI / 4, -M_PI / 4}) {
    parts.push_back(Primitive::OrientedBox(Eigen::Vector3d(0, 0, 0.25 * half_core.z()),
                                           so3::Exp(Eigen::Vector3d(0, 0, angle)), half_arm,
                                           body));
  }
  return parts;
}

void MovingObject::Finalize() {
  bounding_radius_m = 0.0;
  for (const Primitive& p : parts_b) {
    const Aabb& b = p.bounds();
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c((corner & 1) ? b.max.x() : b.min.x(),
                              (corner & 2) ? b.max.y() : b.min.y(),
                              (corner & 4) ? b.max.z() : b.min.z());
      bounding_radius_m = std::max(bounding_radius_m, c.norm());
    }
  }
}

}  // namespace swarmlio::sim
