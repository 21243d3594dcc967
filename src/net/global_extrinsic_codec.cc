// GlobalExtrinsic payload (layout in swarmlio/net/wire_format.h).
#include <string>

#include "src/net/field_codec.h"
#include "src/net/payload_codecs.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {
namespace {

// The entry's bits byte: quaternion largest index, source.
constexpr uint8_t kGraphSourceFlag = 0x04;
constexpr uint8_t kKnownBits = kQuaternionLargestMask | kGraphSourceFlag;

Status DecodeEntry(PacketReader* r, GlobalExtrinsicEntry* e) {
  uint8_t id = 0;
  uint8_t bits = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("teammate_id", &id));
  SWARMLIO_RETURN_IF_ERROR(r->U8("bits", &bits));
  if ((bits & ~kKnownBits) != 0) {
    return Status::DataLoss("field 'bits': unknown bits set (" + std::to_string(bits) + ")");
  }
  e->teammate_id = id;
  e->source =
      (bits & kGraphSourceFlag) != 0 ? ExtrinsicSource::kGraph : ExtrinsicSource::kTrajectoryMatch;
  SWARMLIO_RETURN_IF_ERROR(
      ReadQuaternion("q_Ga_Gb", bits & kQuaternionLargestMask, r, &e->q_Ga_Gb));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("p_Gb_in_Ga", r, &e->p_Gb_in_Ga));
  return ReadCovariance<6>("covariance", r, &e->covariance);
}

}  // namespace

void EncodeGlobalExtrinsic(const GlobalExtrinsicMessage& m, PacketWriter* w) {
  w->I64(m.stamp_ns);
  WriteVectorF32(m.g_in_Gi, w);
  WriteCovariance<3>(m.cov_g_in_Gi, w);
  w->U8(static_cast<uint8_t>(m.entries.size()));
  for (const GlobalExtrinsicEntry& e : m.entries) {
    const QuaternionCodes q = EncodeQuaternion(e.q_Ga_Gb);
    w->U8(static_cast<uint8_t>(e.teammate_id));
    w->U8(static_cast<uint8_t>(q.largest |
                               (e.source == ExtrinsicSource::kGraph ? kGraphSourceFlag : 0)));
    WriteQuaternion(q, w);
    WriteVectorF32(e.p_Gb_in_Ga, w);
    WriteCovariance<6>(e.covariance, w);
  }
}

Status DecodeGlobalExtrinsic(int sender_id, PacketReader* r, GlobalExtrinsicMessage* out) {
  GlobalExtrinsicMessage m;
  m.sender_id = sender_id;
  SWARMLIO_RETURN_IF_ERROR(r->I64("stamp_ns", &m.stamp_ns));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("g_in_Gi", r, &m.g_in_Gi));
  SWARMLIO_RETURN_IF_ERROR(ReadCovariance<3>("cov_g_in_Gi", r, &m.cov_g_in_Gi));
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
    const Status s = DecodeEntry(r, &m.entries[static_cast<size_t>(i)]);
    if (!s.ok()) return s.WithContext("entries[" + std::to_string(i) + "]");
  }
  SWARMLIO_RETURN_IF_ERROR(r->ExpectEnd("payload"));
  *out = std::move(m);
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
