// Airframe payload (layout in swarmlio/net/wire_format.h).
#include <cmath>
#include <string>

#include "src/net/field_codec.h"
#include "src/net/payload_codecs.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {
namespace {

/// uint16 code round(x / kAirframeLengthStepM); precondition (CheckMessage):
/// 0 <= x, code <= kAirframeLengthMaxCode.
void WriteLength(double x, PacketWriter* w) {
  w->U16(static_cast<uint16_t>(std::lround(x / kAirframeLengthStepM)));
}

Status ReadLength(const char* field, int index, PacketReader* r, double* x) {
  uint16_t code = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U16(field, index, &code));
  *x = code * kAirframeLengthStepM;
  return Status::Ok();
}

}  // namespace

void EncodeAirframe(const AirframeMessage& m, PacketWriter* w) {
  w->I64(m.stamp_ns);
  w->U8(static_cast<uint8_t>(m.reflector_shape));
  w->U8(static_cast<uint8_t>(std::lround(m.min_intensity)));
  for (int i = 0; i < 3; ++i) WriteLength(m.reflector_half_extents_m[i], w);
  WriteScaledVectorI16(m.reflector_centre_in_body_m, kAirframeLengthStepM, w);
  WriteLength(m.depth_offset_m, w);
  WriteLength(m.size_m, w);
  WriteLength(m.centroid_sigma_m, w);
}

Status DecodeAirframe(int sender_id, PacketReader* r, AirframeMessage* out) {
  AirframeMessage m;
  m.sender_id = sender_id;
  SWARMLIO_RETURN_IF_ERROR(r->I64("stamp_ns", &m.stamp_ns));
  uint8_t shape = 0;
  uint8_t intensity = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("reflector_shape", &shape));
  if (shape > kAirframeMaxShape) {
    return r->Invalid(
        "reflector_shape", -1,
        "has the unknown value " + std::to_string(shape) + " (0 band, 1 box, 2 round)");
  }
  m.reflector_shape = shape;
  SWARMLIO_RETURN_IF_ERROR(r->U8("min_intensity", &intensity));
  m.min_intensity = intensity;
  for (int i = 0; i < 3; ++i) {
    SWARMLIO_RETURN_IF_ERROR(
        ReadLength("reflector_half_extents_m", i, r, &m.reflector_half_extents_m[i]));
  }
  SWARMLIO_RETURN_IF_ERROR(ReadScaledVectorI16("reflector_centre_in_body_m", kAirframeLengthStepM,
                                               r, &m.reflector_centre_in_body_m));
  SWARMLIO_RETURN_IF_ERROR(ReadLength("depth_offset_m", -1, r, &m.depth_offset_m));
  SWARMLIO_RETURN_IF_ERROR(ReadLength("size_m", -1, r, &m.size_m));
  SWARMLIO_RETURN_IF_ERROR(ReadLength("centroid_sigma_m", -1, r, &m.centroid_sigma_m));
  SWARMLIO_RETURN_IF_ERROR(r->ExpectEnd("payload"));
  *out = m;
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
