// EgoState payload (layout in swarmlio/net/wire_format.h).
#include <string>

#include "src/net/field_codec.h"
#include "src/net/payload_codecs.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {

namespace {
constexpr uint8_t kDegeneratedFlag = 0x01;
Status DecodeObservation(WireReader* r, TeammateObservation* o) {
  uint8_t id = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("observed_id", &id));
  o->observed_id = id;
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("p_bk_in_bj", r, &o->p_bk_in_bj));
  return ReadUpperTriangleF32<3>("cov_p_bk_in_bj", r, &o->cov_p_bk_in_bj);
}

}  // namespace

void EncodeEgoState(const EgoStateMessage& m, WireWriter* w) {
  w->I64(m.stamp_ns);
  w->I64(m.session_start_ns);
  WriteQuaternionF32(m.q_Gj_bj, w);
  WriteVectorF64(m.p_bj_in_Gj, w);
  WriteVectorF32(m.v_bj_in_Gj, w);
  WriteVectorF32(m.omega_bj_in_bj, w);
  WriteUpperTriangleF32<3>(m.cov_theta_Gj_bj, w);
  WriteUpperTriangleF32<3>(m.cov_p_bj_in_Gj, w);
  WriteUpperTriangleF32<3>(m.cov_v_bj_in_Gj, w);
  w->U8(m.degenerated ? kDegeneratedFlag : 0);
  w->U8(static_cast<uint8_t>(m.observations.size()));
  for (const TeammateObservation& o : m.observations) {
    w->U8(static_cast<uint8_t>(o.observed_id));
    WriteVectorF32(o.p_bk_in_bj, w);
    WriteUpperTriangleF32<3>(o.cov_p_bk_in_bj, w);
  }
}

Status DecodeEgoState(int sender_id, WireReader* r, EgoStateMessage* out) {
  EgoStateMessage m;
  m.sender_id = sender_id;
  SWARMLIO_RETURN_IF_ERROR(r->I64("stamp_ns", &m.stamp_ns));
  SWARMLIO_RETURN_IF_ERROR(r->I64("session_start_ns", &m.session_start_ns));
  SWARMLIO_RETURN_IF_ERROR(ReadQuaternionF32("q_Gj_bj", r, &m.q_Gj_bj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF64("p_bj_in_Gj", r, &m.p_bj_in_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("v_bj_in_Gj", r, &m.v_bj_in_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("omega_bj_in_bj", r, &m.omega_bj_in_bj));
  SWARMLIO_RETURN_IF_ERROR(ReadUpperTriangleF32<3>("cov_theta_Gj_bj", r, &m.cov_theta_Gj_bj));
  SWARMLIO_RETURN_IF_ERROR(ReadUpperTriangleF32<3>("cov_p_bj_in_Gj", r, &m.cov_p_bj_in_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadUpperTriangleF32<3>("cov_v_bj_in_Gj", r, &m.cov_v_bj_in_Gj));
  uint8_t flags = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("flags", &flags));
  if ((flags & ~kDegeneratedFlag) != 0) {
    return Status::DataLoss("field 'flags': unknown bits set (" + std::to_string(flags) + ")");
  }
  m.degenerated = (flags & kDegeneratedFlag) != 0;
  uint8_t count = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("observation count", &count));
  if (count > EgoStateMessage::kMaxObservations) {
    return Status::DataLoss("observation count " + std::to_string(count) + " exceeds the maximum " +
                            std::to_string(EgoStateMessage::kMaxObservations));
  }
  if (static_cast<size_t>(count) * kObservationBytes != r->remaining()) {
    return Status::DataLoss("observation count " + std::to_string(count) + " needs " +
                            std::to_string(count * kObservationBytes) + " bytes but " +
                            std::to_string(r->remaining()) + " remain");
  }
  m.observations.resize(count);
  for (int i = 0; i < count; ++i) {
    const Status s = DecodeObservation(r, &m.observations[i]);
    if (!s.ok()) return s.WithContext("observations[" + std::to_string(i) + "]");
  }
  SWARMLIO_RETURN_IF_ERROR(r->ExpectEnd("payload"));
  *out = std::move(m);
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
