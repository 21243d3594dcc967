#include "src/io/pointcloud2_codec.h"

#include <sensor_msgs/PointField.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "src/io/header_codec.h"
#include "src/io/ros_message_reader.h"
#include "src/io/ros_time.h"

namespace swarmlio::io::internal {
namespace {

// Smallest serialized PointField: empty name (4) + offset (4) + datatype (1)
// + count (4).
constexpr size_t kMinPointFieldBytes = 13;

struct WireField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 0;
};

// Size in bytes of a PointField datatype, 0 for an unknown code.
size_t DatatypeBytes(uint8_t datatype) {
  switch (datatype) {
    case sensor_msgs::PointField::INT8:
    case sensor_msgs::PointField::UINT8:
      return 1;
    case sensor_msgs::PointField::INT16:
    case sensor_msgs::PointField::UINT16:
      return 2;
    case sensor_msgs::PointField::INT32:
    case sensor_msgs::PointField::UINT32:
    case sensor_msgs::PointField::FLOAT32:
      return 4;
    case sensor_msgs::PointField::FLOAT64:
      return 8;
    default:
      return 0;
  }
}

// Where a used field sits inside a point.
struct FieldAccessor {
  bool present = false;
  uint32_t offset = 0;
  uint8_t datatype = 0;
};

double LoadAsDouble(const uint8_t* point, const FieldAccessor& field) {
  const uint8_t* p = point + field.offset;
  switch (field.datatype) {
    case sensor_msgs::PointField::INT8:
      return static_cast<int8_t>(p[0]);
    case sensor_msgs::PointField::UINT8:
      return p[0];
    case sensor_msgs::PointField::INT16:
      return static_cast<int16_t>(LoadLittleEndian<uint16_t>(p));
    case sensor_msgs::PointField::UINT16:
      return LoadLittleEndian<uint16_t>(p);
    case sensor_msgs::PointField::INT32:
      return static_cast<int32_t>(LoadLittleEndian<uint32_t>(p));
    case sensor_msgs::PointField::UINT32:
      return LoadLittleEndian<uint32_t>(p);
    case sensor_msgs::PointField::FLOAT32:
      return LoadFloat32(p);
    case sensor_msgs::PointField::FLOAT64:
      return LoadFloat64(p);
    default:
      return 0.0;  // unreachable: datatypes are validated before use
  }
}

float LoadAsFloat(const uint8_t* point, const FieldAccessor& field) {
  if (field.datatype == sensor_msgs::PointField::FLOAT32) {
    return LoadFloat32(point + field.offset);
  }
  return static_cast<float>(LoadAsDouble(point, field));
}

uint8_t LoadAsByte(const uint8_t* point, const FieldAccessor& field) {
  const double value = LoadAsDouble(point, field);
  if (!(value > 0.0)) return 0;  // also NaN
  if (value >= 255.0) return 255;
  return static_cast<uint8_t>(value);
}

std::string FieldNames(const std::vector<WireField>& fields) {
  std::string names;
  for (const WireField& f : fields) {
    if (!names.empty()) names += ", ";
    names += f.name;
  }
  return "[" + names + "]";
}

const WireField* FindField(const std::vector<WireField>& fields, const std::string& name) {
  for (const WireField& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

// Resolves the first of `names` present in `fields` and checks that it fits
// inside a point of `point_step` bytes.
Status ResolveField(const std::vector<WireField>& fields,
                    std::initializer_list<const char*> names,
                    uint32_t point_step,
                    FieldAccessor* accessor,
                    std::string* resolved_name = nullptr) {
  *accessor = FieldAccessor();
  for (const char* name : names) {
    const WireField* f = FindField(fields, name);
    if (f == nullptr) continue;
    const size_t bytes = DatatypeBytes(f->datatype);
    if (bytes == 0) {
      return Status::DataLoss(std::string("PointCloud2 field '") + name +
                              "' has unknown datatype " + std::to_string(f->datatype));
    }
    if (f->count == 0) {
      return Status::DataLoss(std::string("PointCloud2 field '") + name + "' has count 0");
    }
    if (static_cast<uint64_t>(f->offset) + bytes > point_step) {
      return Status::DataLoss(std::string("PointCloud2 field '") + name + "' (offset " +
                              std::to_string(f->offset) + ", " + std::to_string(bytes) +
                              " bytes) does not fit in point_step " + std::to_string(point_step));
    }
    accessor->present = true;
    accessor->offset = f->offset;
    accessor->datatype = f->datatype;
    if (resolved_name != nullptr) *resolved_name = name;
    return Status::Ok();
  }
  return Status::Ok();
}

template <class T>
void Store(uint8_t* dst, T value) {
  // PointCloud2 data is little endian (is_bigendian = false); so is the host
  // (checked in EncodePointCloud2).
  std::memcpy(dst, &value, sizeof(T));
}

sensor_msgs::PointField MakeField(const std::string& name, uint32_t offset, uint8_t datatype) {
  sensor_msgs::PointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = datatype;
  field.count = 1;
  return field;
}

}  // namespace

Status DecodePointCloud2(const uint8_t* data,
                         size_t size,
                         const PointCloud2DecodeOptions& options,
                         LidarScan* scan,
                         PointCloud2DecodeInfo* info,
                         WireEncoding encoding) {
  RosMessageReader reader(data, size);
  SWARMLIO_RETURN_IF_ERROR(reader.Begin(encoding));
  SWARMLIO_RETURN_IF_ERROR(ReadRosHeader(&reader, &scan->stamp_ns, &scan->frame_id));
  scan->livox_timebase_ns = 0;
  scan->livox_lidar_id = 0;
  uint32_t height = 0;
  uint32_t width = 0;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("height", &height));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("width", &width));
  uint32_t num_fields = 0;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadArrayLength("fields", kMinPointFieldBytes, &num_fields));
  std::vector<WireField> fields(num_fields);
  for (WireField& f : fields) {
    SWARMLIO_RETURN_IF_ERROR(reader.ReadString("fields.name", &f.name));
    SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("fields.offset", &f.offset));
    SWARMLIO_RETURN_IF_ERROR(reader.ReadU8("fields.datatype", &f.datatype));
    SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("fields.count", &f.count));
  }
  uint8_t is_bigendian = 0;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  uint32_t data_bytes = 0;
  const uint8_t* cloud = nullptr;
  uint8_t is_dense = 0;
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU8("is_bigendian", &is_bigendian));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("point_step", &point_step));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU32("row_step", &row_step));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadArrayLength("data", 1, &data_bytes));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadBytes("data", data_bytes, &cloud));
  SWARMLIO_RETURN_IF_ERROR(reader.ReadU8("is_dense", &is_dense));
  SWARMLIO_RETURN_IF_ERROR(reader.ExpectEnd("sensor_msgs/PointCloud2"));

  if (is_bigendian != 0) {
    return Status::InvalidArgument("big-endian PointCloud2 (is_bigendian = true) is not supported");
  }

  FieldAccessor x, y, z, intensity, tag, line, time;
  SWARMLIO_RETURN_IF_ERROR(ResolveField(fields, {"x"}, point_step, &x));
  SWARMLIO_RETURN_IF_ERROR(ResolveField(fields, {"y"}, point_step, &y));
  SWARMLIO_RETURN_IF_ERROR(ResolveField(fields, {"z"}, point_step, &z));
  if (!x.present || !y.present || !z.present) {
    return Status::InvalidArgument("PointCloud2 lacks an x, y or z field; fields are " +
                                   FieldNames(fields));
  }
  SWARMLIO_RETURN_IF_ERROR(
      ResolveField(fields, {"intensity", "reflectivity"}, point_step, &intensity));
  SWARMLIO_RETURN_IF_ERROR(ResolveField(fields, {"tag"}, point_step, &tag));
  SWARMLIO_RETURN_IF_ERROR(ResolveField(fields, {"line", "ring"}, point_step, &line));
  info->time_field.clear();
  if (options.time_field.empty()) {
    SWARMLIO_RETURN_IF_ERROR(ResolveField(fields, {"time", "t", "timestamp", "offset_time"},
                                          point_step, &time, &info->time_field));
  } else {
    SWARMLIO_RETURN_IF_ERROR(
        ResolveField(fields, {options.time_field.c_str()}, point_step, &time, &info->time_field));
    if (!time.present) {
      return Status::InvalidArgument("PointCloud2 has no configured point time field '" +
                                     options.time_field + "'; fields are " + FieldNames(fields));
    }
  }
  info->has_time_field = time.present;

  scan->points.clear();
  const uint64_t num_points = static_cast<uint64_t>(width) * height;
  if (num_points == 0) return Status::Ok();
  const uint64_t row_bytes = static_cast<uint64_t>(width) * point_step;
  if (row_step < row_bytes) {
    return Status::DataLoss("PointCloud2 row_step " + std::to_string(row_step) +
                            " < width * point_step " + std::to_string(row_bytes));
  }
  const uint64_t needed = static_cast<uint64_t>(height - 1) * row_step + row_bytes;
  if (needed > data_bytes) {
    return Status::DataLoss("PointCloud2 " + std::to_string(width) + "x" + std::to_string(height) +
                            " points need " + std::to_string(needed) + " data bytes, message has " +
                            std::to_string(data_bytes));
  }

  const double ticks_per_s = TimestampUnitTicksPerSecond(options.time_unit);
  scan->points.resize(num_points);
  size_t index = 0;
  for (uint32_t row = 0; row < height; ++row) {
    const uint8_t* row_data = cloud + static_cast<uint64_t>(row) * row_step;
    for (uint32_t col = 0; col < width; ++col) {
      const uint8_t* p = row_data + static_cast<uint64_t>(col) * point_step;
      LidarPoint& point = scan->points[index++];
      point.x = LoadAsFloat(p, x);
      point.y = LoadAsFloat(p, y);
      point.z = LoadAsFloat(p, z);
      point.reflectivity = intensity.present ? LoadAsFloat(p, intensity) : 0.f;
      point.tag = tag.present ? LoadAsByte(p, tag) : 0;
      point.line = line.present ? LoadAsByte(p, line) : 0;
      point.offset_time_s = time.present ? LoadAsDouble(p, time) / ticks_per_s : 0.0;
    }
  }
  return Status::Ok();
}

Status EncodePointCloud2(const LidarScan& scan,
                         uint32_t seq,
                         TimestampUnit time_unit,
                         const std::string& time_field,
                         sensor_msgs::PointCloud2* msg) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "little-endian host required");
  constexpr uint32_t kPointStep = 32;
  if (scan.points.size() > std::numeric_limits<uint32_t>::max() / kPointStep) {
    return Status::InvalidArgument("scan has too many points for one PointCloud2");
  }
  *msg = sensor_msgs::PointCloud2();
  msg->header.seq = seq;
  SWARMLIO_RETURN_IF_ERROR(RosTimeFromStampNs(scan.stamp_ns, &msg->header.stamp));
  msg->header.frame_id = scan.frame_id;
  using sensor_msgs::PointField;
  msg->fields = {MakeField("x", 0, PointField::FLOAT32),
                 MakeField("y", 4, PointField::FLOAT32),
                 MakeField("z", 8, PointField::FLOAT32),
                 MakeField("intensity", 12, PointField::FLOAT32)};
  if (!time_field.empty()) msg->fields.push_back(MakeField(time_field, 16, PointField::FLOAT64));
  msg->fields.push_back(MakeField("tag", 24, PointField::UINT8));
  msg->fields.push_back(MakeField("line", 25, PointField::UINT8));
  const uint32_t n = static_cast<uint32_t>(scan.points.size());
  msg->height = 1;
  msg->width = n;
  msg->is_bigendian = false;
  msg->point_step = kPointStep;
  msg->row_step = kPointStep * n;
  msg->data.assign(static_cast<size_t>(msg->row_step), 0);
  const double ticks_per_s = TimestampUnitTicksPerSecond(time_unit);
  bool dense = true;
  for (uint32_t i = 0; i < n; ++i) {
    const LidarPoint& point = scan.points[i];
    uint8_t* p = msg->data.data() + static_cast<size_t>(i) * kPointStep;
    Store(p + 0, point.x);
    Store(p + 4, point.y);
    Store(p + 8, point.z);
    Store(p + 12, point.reflectivity);
    if (!time_field.empty()) Store(p + 16, point.offset_time_s * ticks_per_s);
    p[24] = point.tag;
    p[25] = point.line;
    dense = dense && std::isfinite(point.x) && std::isfinite(point.y) && std::isfinite(point.z);
  }
  msg->is_dense = dense;
  return Status::Ok();
}

AzimuthTimeInfo ReconstructPointTimeFromAzimuth(double scan_period_s, LidarScan* scan) {
  AzimuthTimeInfo info;
  constexpr double kTwoPi = 2.0 * M_PI;
  constexpr double kMinRadius = 1e-6;  // points on the rotation axis have no azimuth [m]
  constexpr int kRings = 256;          // LidarPoint::line is a byte
  std::vector<LidarPoint>& points = scan->points;
  std::vector<double> azimuth(points.size(), 0.0);
  std::vector<bool> valid(points.size(), false);
  std::vector<double> steps;
  steps.reserve(points.size());
  std::array<int, kRings> previous;
  previous.fill(-1);
  int first = -1;
  for (size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].x, y = points[i].y;
    if (!(std::hypot(x, y) > kMinRadius)) continue;
    valid[i] = true;
    azimuth[i] = std::atan2(y, x);
    if (first < 0) first = static_cast<int>(i);
    int& prev = previous[points[i].line];
    if (prev >= 0) {
      // Step to the previous point of the same ring, wrapped to (-pi, pi].
      const double step = std::remainder(azimuth[i] - azimuth[prev], kTwoPi);
      if (step != 0.0) steps.push_back(step);
    }
    prev = static_cast<int>(i);
  }
  for (LidarPoint& p : points) p.offset_time_s = 0.0;
  if (first < 0 || steps.empty()) return info;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  info.direction = steps[steps.size() / 2] < 0.0 ? -1 : 1;
  info.reconstructed = true;
  // Per ring, the time of its latest point: a point that seems more than half
  // a turn ahead of it is slightly behind (clamped to it), one more than half
  // a turn behind it has wrapped past a full turn (a period added).
  std::array<double, kRings> last_t;
  last_t.fill(0.0);
  const double half = 0.5 * scan_period_s;
  double t_previous = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!valid[i]) {
      points[i].offset_time_s = t_previous;  // no azimuth: the previous point's time
      continue;
    }
    double swept = std::fmod(info.direction * (azimuth[i] - azimuth[first]), kTwoPi);
    if (swept < 0.0) swept += kTwoPi;  // [0, 2 pi)
    double t = swept / kTwoPi * scan_period_s;
    double& last = last_t[points[i].line];
    if (t - last > half) {
      t = last;
    } else if (last - t > half) {
      t += scan_period_s;
      last = t;
    } else {
      last = std::max(last, t);
    }
    points[i].offset_time_s = t;
    t_previous = t;
    info.span_s = std::max(info.span_s, t);
  }
  return info;
}

}  // namespace swarmlio::io::internal
