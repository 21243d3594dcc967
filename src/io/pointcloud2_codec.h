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

/// Decodes the serialized bytes of one PointCloud2. Points are returned as
/// stored (NaN included). A configured time field that is absent is an error.
Status DecodePointCloud2(const uint8_t* data,
                         size_t size,
                         const PointCloud2DecodeOptions& options,
                         LidarScan* scan,
                         PointCloud2DecodeInfo* info);

/// Fills an unorganized (height 1) cloud with 32-byte points: x y z
/// intensity (FLOAT32 at 0 4 8 12), `time_field` (FLOAT64 at 16, offset in
/// `time_unit`), tag and line (UINT8 at 24 25), 6 bytes of zero padding.
Status EncodePointCloud2(const LidarScan& scan,
                         uint32_t seq,
                         TimestampUnit time_unit,
                         const std::string& time_field,
                         sensor_msgs::PointCloud2* msg);

}  // namespace swarmlio::io::internal
