// GlobalExtrinsic payload (layout in swarmlio/net/wire_format.h).
#include <string>

#include "src/net/field_codec.h"
#include "src/net/payload_codecs.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {
namespace {

Status DecodeEntry(WireReader* r, GlobalExtrinsicEntry* e) {
  uint8_t id = 0;
  uint8_t source = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("teammate_id", &id));
  SWARMLIO_RETURN_IF_ERROR(r->U8("source", &source));
  if (source != static_cast<uint8_t>(ExtrinsicSource::kTrajectoryMatch) &&
      source != static_cast<uint8_t>(ExtrinsicSource::kGraph)) {
    return Status::DataLoss("field 'source': unknown value " + std::to_string(source));
  }
  e->teammate_id = id;
  e->source = static_cast<ExtrinsicSource>(source);
  SWARMLIO_RETURN_IF_ERROR(ReadQuaternionF32("q_Gi_Gj", r, &e->q_Gi_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF64("p_Gj_in_Gi", r, &e->p_Gj_in_Gi));
  return ReadUpperTriangleF32<6>("covariance", r, &e->covariance);
}

}  // namespace

void EncodeGlobalExtrinsic(const GlobalExtrinsicMessage& m, WireWriter* w) {
  w->I64(m.stamp_ns);
  WriteVectorF32(m.g_in_Gi, w);
  WriteUpperTriangleF32<3>(m.cov_g_in_Gi, w);
  w->U8(static_cast<uint8_t>(m.entries.size()));
  for (const GlobalExtrinsicEntry& e : m.entries) {
    w->U8(static_cast<uint8_t>(e.teammate_id));
    w->U8(static_cast<uint8_t>(e.source));
    WriteQuaternionF32(e.q_Gi_Gj, w);
    WriteVectorF64(e.p_Gj_in_Gi, w);
    WriteUpperTriangleF32<6>(e.covariance, w);
  }
}

Status DecodeGlobalExtrinsic(int sender_id, WireReader* r, GlobalExtrinsicMessage* out) {
  GlobalExtrinsicMessage m;
  m.sender_id = sender_id;
  SWARMLIO_RETURN_IF_ERROR(r->I64("stamp_ns", &m.stamp_ns));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("g_in_Gi", r, &m.g_in_Gi));
  SWARMLIO_RETURN_IF_ERROR(ReadUpperTriangleF32<3>("cov_g_in_Gi", r, &m.cov_g_in_Gi));
  uint8_t count = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("entry count", &count));
  if (count > GlobalExtrinsicMessage::kMaxEntries) {
    return Status::DataLoss("entry count " + std::to_string(count) + " exceeds the maximum " +
                            std::to_string(GlobalExtrinsicMessage::kMaxEntries));
  }
  if (static_cast<size_t>(count) * kExtrinsicEntryBytes != r->remaining()) {
    return Status::DataLoss("entry count " + std::to_string(count) + " needs " +
                            std::to_string(count * kExtrinsicEntryBytes) + " bytes but " +
                            std::to_string(r->remaining()) + " remain");
  }
  m.entries.resize(count);
  for (int i = 0; i < count; ++i) {
    const Status s = DecodeEntry(r, &m.entries[i]);
    if (!s.ok()) return s.WithContext("entries[" + std::to_string(i) + "]");
  }
  SWARMLIO_RETURN_IF_ERROR(r->ExpectEnd("payload"));
  *out = std::move(m);
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
