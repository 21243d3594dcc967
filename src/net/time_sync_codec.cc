// TimeSync payload (layout in swarmlio/net/wire_format.h).
#include <string>

#include "src/net/payload_codecs.h"

namespace swarmlio::net::internal {

void EncodeTimeSync(const TimeSyncMessage& m, PacketWriter* w) {
  w->U8(static_cast<uint8_t>(m.target_id));
  w->U8(m.is_response ? 1 : 0);
  w->I64(m.t1_ns);
  w->I64(m.t2_ns);
  w->I64(m.t3_ns);
}

Status DecodeTimeSync(int sender_id, PacketReader* r, TimeSyncMessage* out) {
  TimeSyncMessage m;
  m.sender_id = sender_id;
  uint8_t target = 0;
  uint8_t kind = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("target_id", &target));
  SWARMLIO_RETURN_IF_ERROR(r->U8("kind", &kind));
  if (kind > 1) return Status::DataLoss("field 'kind': unknown value " + std::to_string(kind));
  m.target_id = target;
  m.is_response = kind == 1;
  SWARMLIO_RETURN_IF_ERROR(r->I64("t1_ns", &m.t1_ns));
  SWARMLIO_RETURN_IF_ERROR(r->I64("t2_ns", &m.t2_ns));
  SWARMLIO_RETURN_IF_ERROR(r->I64("t3_ns", &m.t3_ns));
  SWARMLIO_RETURN_IF_ERROR(r->ExpectEnd("payload"));
  *out = m;
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
