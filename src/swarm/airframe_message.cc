#include "airframe_message.h"

namespace swarmlio::swarm::internal {

// The wire's shape codes (net::AirframeMessage::reflector_shape).
static_assert(static_cast<int>(teammate::ReflectorShape::kBand) == 0 &&
                  static_cast<int>(teammate::ReflectorShape::kBox) == 1 &&
                  static_cast<int>(teammate::ReflectorShape::kRound) == 2,
              "the wire's reflector shape codes are 0 band, 1 box, 2 round");

net::AirframeMessage ToAirframeMessage(int sender_id,
                                       int64_t stamp_ns,
                                       const teammate::AirframeDescription& airframe) {
  net::AirframeMessage m;
  m.sender_id = sender_id;
  m.stamp_ns = stamp_ns;
  m.reflector_shape = static_cast<int>(airframe.reflector_shape);
  m.reflector_half_extents_m = airframe.reflector_half_extents_m;
  m.reflector_centre_in_body_m = airframe.reflector_centre_in_body_m;
  m.depth_offset_m = airframe.depth_offset_m;
  m.size_m = airframe.size_m;
  m.min_intensity = airframe.min_intensity;
  m.centroid_sigma_m = airframe.centroid_sigma_m;
  return m;
}

bool FromAirframeMessage(const net::AirframeMessage& message,
                         teammate::AirframeDescription* airframe) {
  teammate::AirframeDescription a;
  switch (message.reflector_shape) {
    case static_cast<int>(teammate::ReflectorShape::kBand):
      a.reflector_shape = teammate::ReflectorShape::kBand;
      break;
    case static_cast<int>(teammate::ReflectorShape::kBox):
      a.reflector_shape = teammate::ReflectorShape::kBox;
      break;
    case static_cast<int>(teammate::ReflectorShape::kRound):
      a.reflector_shape = teammate::ReflectorShape::kRound;
      break;
    default:
      return false;
  }
  a.reflector_half_extents_m = message.reflector_half_extents_m;
  a.reflector_centre_in_body_m = message.reflector_centre_in_body_m;
  a.depth_offset_m = message.depth_offset_m;
  a.size_m = message.size_m;
  a.min_intensity = message.min_intensity;
  a.centroid_sigma_m = message.centroid_sigma_m;
  if (!a.Validate().empty()) return false;
  *airframe = a;
  return true;
}

}  // namespace swarmlio::swarm::internal
