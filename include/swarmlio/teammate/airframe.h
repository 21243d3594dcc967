// What a drone tells its teammates about its own body (YAML `airframe:` of a
// drone entry, broadcast as net::AirframeMessage), so that an observer's
// detector gates, observation offset and observation noise follow the body it
// sees instead of one global default (docs/teammate.md "Airframes").
//
// The reflective parts are described by one shape in the body frame b,
// centred at `reflector_centre_in_body_m`, and a LiDAR sees the returns'
// centroid in front of that centre, towards the observer. With u the unit
// direction from the teammate to the observer in b (`u_in_b`):
//  - band: the vertical side faces of a box of half extents (a, b) (a tape
//    band around the core). Faces x = +-a and y = +-b are seen with projected
//    areas proportional to b |u_x| and a |u_y|, so the returns' centroid lies
//        a b (u_x, u_y, 0) / (b |u_x| + a |u_y|)
//    from the centre (teammate/observation.h has the derivation);
//  - box: all six faces of a box of half extents (a, b, c):
//        a b c u / (b c |u_x| + a c |u_y| + a b |u_z|);
//  - round: anything else (a see-through shell, taped arm ends seen on the
//    near and far side): `depth_offset_m` along u.
// The figure for a real airframe comes from measuring it (or from the
// recorded returns of a flight); for the simulator's airframes
// sim::DescribeAirframe gives it from the body model.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::teammate {

enum class ReflectorShape { kBand, kBox, kRound };

}  // namespace swarmlio::teammate

namespace swarmlio::config {
template <>
struct EnumTraits<teammate::ReflectorShape> {
  static constexpr std::array<std::pair<teammate::ReflectorShape, const char*>, 3> kNames{{
      {teammate::ReflectorShape::kBand, "band"},
      {teammate::ReflectorShape::kBox, "box"},
      {teammate::ReflectorShape::kRound, "round"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::teammate {

/// YAML `airframe:` of a drone entry: this drone's own body. The defaults
/// describe the simulator's default airframe (tape_band, docs/simulator.md).
struct AirframeDescription {
  ReflectorShape reflector_shape = ReflectorShape::kBand;
  Eigen::Vector3d reflector_half_extents_m = Eigen::Vector3d(0.102, 0.072, 0.025);  // a, b, c [m]
  Eigen::Vector3d reflector_centre_in_body_m = Eigen::Vector3d::Zero();             // [m]
  double depth_offset_m = 0.07;   // round: returns' centroid in front of the centre [m]
  double size_m = 0.45;           // bounding-box diagonal of the whole airframe [m]
  double min_intensity = 151.0;   // lowest intensity its reflectors return (Livox 0-255)
  double centroid_sigma_m = 0.0;  // per-scan scatter of the returns' centroid beyond the
                                  // LiDAR's own noise (sparse reflectors) [m]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("reflector_shape", reflector_shape,
      FieldSpec::Doc("band (tape around the core), box (all faces) or round (anything else)"));
    v("reflector_half_extents_m", reflector_half_extents_m,
      FieldSpec::InRange(0.0, 2.0, "m", "half extents of the reflective parts along body x, y, z"));
    v("reflector_centre_in_body_m", reflector_centre_in_body_m,
      FieldSpec::InRange(-2.0, 2.0, "m", "centre of the reflective parts in the body (IMU) frame"));
    v("depth_offset_m", depth_offset_m,
      FieldSpec::InRange(0.0, 1.0, "m", "round: the returns' centroid lies this far in front"));
    v("size_m", size_m,
      FieldSpec::InRange(0.05, 5.0, "m", "bounding-box diagonal of the airframe"));
    v("min_intensity", min_intensity,
      FieldSpec::InRange(0.0, 255.0, "", "lowest intensity of the reflective parts (Livox 0-255)"));
    v("centroid_sigma_m", centroid_sigma_m,
      FieldSpec::InRange(0.0, 1.0, "m",
                         "per-scan scatter of the returns' centroid (sparse reflectors)"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// Where the centroid of the returns on the reflective parts lies in b,
/// seen from the unit direction `u_in_b` (teammate -> observer); see the
/// file comment.
Eigen::Vector3d VisibleReflectorCentroid(const AirframeDescription& airframe,
                                         const Eigen::Vector3d& u_in_b);

}  // namespace swarmlio::teammate
