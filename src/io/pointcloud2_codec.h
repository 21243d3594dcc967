// sensor_msgs/PointCloud2 <-> LidarScan.
//
// Accepted clouds: little endian; fields x, y, z (required), intensity or
// reflectivity, tag, line or ring (optional, 0 when absent), and a per-point
// time relative to the header stamp in a configurable unit. Each field may
// have any PointField datatype (INT8 ... FLOAT64); the first element is used.
// point_step, row_step and width * height are respected (padding and row
// gaps are fine). A cloud without a time field decodes with all offsets 0.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "src/io/ros_message_reader.h"
#include "swarmlio/common/status.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

struct PointCloud2DecodeOptions {
  TimestampUnit time_unit = TimestampUnit::kMicrosecond;
  std::string time_field;  // "" = first of "time", "t", "timestamp", "offset_time"
};

struct PointCloud2DecodeInfo {
  bool has_time_field = false;
  std::string time_field;  // the field used (empty if none)
};

/// Decodes the serialized bytes of one PointCloud2 (ROS1, or ROS 2 CDR for
/// sensor_msgs/msg/PointCloud2). Points are returned as
/// stored (NaN included). A configured time field that is absent is an error.
Status DecodePointCloud2(const uint8_t* data,
                         size_t size,
                         const PointCloud2DecodeOptions& options,
                         LidarScan* scan,
                         PointCloud2DecodeInfo* info,
                         WireEncoding encoding = WireEncoding::kRos1);

/// Fills an unorganized (height 1) cloud with 32-byte points: x y z
/// intensity (FLOAT32 at 0 4 8 12), `time_field` (FLOAT64 at 16, offset in
/// `time_unit`), tag and line (UINT8 at 24 25), 6 bytes of zero padding.
/// An empty `time_field` writes no time field (bytes 16-23 are padding).
Status EncodePointCloud2(const LidarScan& scan,
                         uint32_t seq,
                         TimestampUnit time_unit,
                         const std::string& time_field,
                         sensor_msgs::PointCloud2* msg);

/// How ReconstructPointTimeFromAzimuth read a scan.
struct AzimuthTimeInfo {
  bool reconstructed = false;  // false: fewer than 2 points off the z axis (times left at 0)
  int direction = 0;           // +1 counter-clockwise (azimuth increasing), -1 clockwise
  double span_s = 0.0;         // largest reconstructed offset [s]
};

/// Per-point time of a spinning LiDAR's scan from the azimuth atan2(y, x) of
/// each point (sensor frame): offset = (azimuth swept since the first point,
/// in the direction of rotation) / 2 pi * scan_period_s, so the first point
/// is at the header stamp. The direction is the sign of the median azimuth
/// step between consecutive points (points come in firing order or ring by
/// ring, both sweep in the rotation direction). Points whose swept angle
/// wraps around (a ring starting slightly before the first point, or a scan
/// a little longer than one turn) are clamped to [0, scan_period_s]: a point
/// in the first half of the cloud that appears almost a full turn ahead gets
/// 0, one in the second half that appears just past the start gets the
/// period.
AzimuthTimeInfo ReconstructPointTimeFromAzimuth(double scan_period_s, LidarScan* scan);

}  // namespace swarmlio::io::internal
