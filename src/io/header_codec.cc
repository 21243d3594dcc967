#include "src/io/header_codec.h"

namespace swarmlio::io::internal {
namespace {

// ROS 2 std_msgs/msg/Header: builtin_interfaces/Time (int32 sec, uint32
// nanosec), string frame_id; no seq.
Status ReadRos2Header(RosMessageReader* reader, int64_t* stamp_ns, std::string* frame_id) {
  uint32_t sec_bits = 0;
  uint32_t nanosec = 0;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU32("header.stamp.sec", &sec_bits));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU32("header.stamp.nanosec", &nanosec));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadString("header.frame_id", frame_id));
  const int32_t sec = static_cast<int32_t>(sec_bits);
  if (sec < 0) {
    return Status::DataLoss("header.stamp.sec " + std::to_string(sec) +
                            " is negative (stamps before 1970 are not supported)");
  }
  *stamp_ns = StampNsFromRos(static_cast<uint32_t>(sec), nanosec);
  return Status::Ok();
}

}  // namespace

Status ReadRosHeader(RosMessageReader* reader, int64_t* stamp_ns, std::string* frame_id) {
  if (reader->encoding() == WireEncoding::kCdr) return ReadRos2Header(reader, stamp_ns, frame_id);
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
