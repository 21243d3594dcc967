#include "swarmlio/teammate/airframe.h"

#include <cmath>

namespace swarmlio::teammate {

Eigen::Vector3d VisibleReflectorCentroid(const AirframeDescription& airframe,
                                         const Eigen::Vector3d& u_in_b) {
  const Eigen::Vector3d& h = airframe.reflector_half_extents_m;
  const Eigen::Vector3d abs_u = u_in_b.cwiseAbs();
  switch (airframe.reflector_shape) {
    case ReflectorShape::kBand: {
      // Side faces only: seen from straight above or below, none.
      const double denominator = h.y() * abs_u.x() + h.x() * abs_u.y();
      if (denominator <= 1e-12) return Eigen::Vector3d::Zero();
      return (h.x() * h.y() / denominator) * Eigen::Vector3d(u_in_b.x(), u_in_b.y(), 0.0);
    }
    case ReflectorShape::kBox: {
      const double denominator =
          h.y() * h.z() * abs_u.x() + h.x() * h.z() * abs_u.y() + h.x() * h.y() * abs_u.z();
      if (denominator <= 1e-12) return Eigen::Vector3d::Zero();
      return (h.x() * h.y() * h.z() / denominator) * u_in_b;
    }
    case ReflectorShape::kRound:
      return airframe.depth_offset_m * u_in_b;
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace swarmlio::teammate
