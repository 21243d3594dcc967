#include "src/io/custom_msg_codec.h"

#include <cmath>
#include <limits>
#include <string>

#include "src/io/header_codec.h"
#include "src/io/ros_message_reader.h"
#include "src/io/ros_time.h"

namespace swarmlio::io::internal {
namespace {

constexpr double kNsPerS = 1e9;

uint8_t ReflectivityToByte(float reflectivity) {
  if (!(reflectivity > 0.f)) return 0;  // also NaN
  if (reflectivity >= 255.f) return 255;
  return static_cast<uint8_t>(std::lround(reflectivity));
}

}  // namespace

Status DecodeLivoxCustomMsg(const uint8_t* data,
                            size_t size,
                            LidarScan* scan,
                            WireEncoding encoding) {
  RosMessageReader reader(data, size);
  SWARMLIO_RETURN_IF_ERROR(reader.Begin(encoding));
  SWARMLIO_RETURN_IF_ERROR(ReadRosHeader(&reader, &scan->stamp_ns, &scan->frame_id));
  uint32_t point_num = 0;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU64("timebase", &scan->livox_timebase_ns));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("point_num", &point_num));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU8("lidar_id", &scan->livox_lidar_id));
  const uint8_t* rsvd = nullptr;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadBytes("rsvd", 3, &rsvd));
  uint32_t count = 0;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadArrayLength("points", kLivoxCustomPointBytes, &count));
  if (count != point_num) {
    return Status::DataLoss("livox CustomMsg: point_num " + std::to_string(point_num) +
                            " != points array length " + std::to_string(count));
  }
  // CDR aligns each point to its uint32 offset_time: 19 bytes + 1 padding
  // between points (the array itself starts aligned, after its count).
  const size_t stride =
      encoding == WireEncoding::kCdr ? kLivoxCustomPointBytes + 1 : kLivoxCustomPointBytes;
  const size_t points_bytes =
      count == 0 ? 0 : (static_cast<size_t>(count) - 1) * stride + kLivoxCustomPointBytes;
  const uint8_t* bytes = nullptr;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadBytes("points", points_bytes, &bytes));
  SWARMLIO_RETURN_IF_ERROR(reader.ExpectEnd(kLivoxCustomMsgDataType));

  scan->points.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    const uint8_t* p = bytes + static_cast<size_t>(i) * stride;
    LidarPoint& point = scan->points[i];
    point.offset_time_s = static_cast<double>(LoadLittleEndian<uint32_t>(p)) / kNsPerS;
    point.x = LoadFloat32(p + 4);
    point.y = LoadFloat32(p + 8);
    point.z = LoadFloat32(p + 12);
    point.reflectivity = static_cast<float>(p[16]);
    point.tag = p[17];
    point.line = p[18];
  }
  return Status::Ok();
}

Status EncodeLivoxCustomMsg(const LidarScan& scan, uint32_t seq, LivoxCustomMsg* msg) {
  *msg = LivoxCustomMsg();
  msg->header.seq = seq;
  SWARMLIO_RETURN_IF_ERROR(RosTimeFromStampNs(scan.stamp_ns, &msg->header.stamp));
  msg->header.frame_id = scan.frame_id;
  msg->timebase = scan.livox_timebase_ns;
  msg->lidar_id = scan.livox_lidar_id;
  msg->point_num = static_cast<uint32_t>(scan.points.size());
  msg->points.resize(scan.points.size());
  constexpr double kMaxOffsetNs = static_cast<double>(std::numeric_limits<uint32_t>::max());
  for (size_t i = 0; i < scan.points.size(); ++i) {
    const LidarPoint& in = scan.points[i];
    const double offset_ns = std::round(in.offset_time_s * kNsPerS);
    if (!(offset_ns >= 0.0 && offset_ns <= kMaxOffsetNs)) {  // also NaN
      return Status::InvalidArgument("point " + std::to_string(i) + ": offset_time_s " +
                                     std::to_string(in.offset_time_s) +
                                     " does not fit the CustomMsg uint32 ns offset");
    }
    LivoxCustomPoint& out = msg->points[i];
    out.offset_time = static_cast<uint32_t>(offset_ns);
    out.x = in.x;
    out.y = in.y;
    out.z = in.z;
    out.reflectivity = ReflectivityToByte(in.reflectivity);
    out.tag = in.tag;
    out.line = in.line;
  }
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
