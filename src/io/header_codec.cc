#include "src/io/header_codec.h"

namespace swarmlio::io::internal {

Status ReadRosHeader(RosMessageReader* reader, int64_t* stamp_ns, std::string* frame_id) {
  uint32_t seq = 0;
  uint32_t sec = 0;
  uint32_t nsec = 0;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU32("header.seq", &seq));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU32("header.stamp.sec", &sec));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU32("header.stamp.nsec", &nsec));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadString("header.frame_id", frame_id));
  *stamp_ns = StampNsFromRos(sec, nsec);
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
