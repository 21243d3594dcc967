// Single serialized ROS1 sensor messages <-> records, for drivers that take
// messages off live topics instead of a bag (the ROS node and the bag
// publisher in tools/ros). The bytes are a message's ROS serialization (what
// a bag stores, what topic_tools::ShapeShifter carries), decoded by the bag
// reader's own decoders with its checks, so a message gives the same record
// live as from a bag:
//   IMU    sensor_msgs/Imu; a non-finite sample or a stamp before the
//          previous one is skipped;
//   LiDAR  livox_ros_driver(2)/CustomMsg or sensor_msgs/PointCloud2;
//          non-finite points are dropped, an empty scan or a stamp before
//          the previous one is skipped; a PointCloud2 without per-point time
//          gets it from azimuth as BagReaderOptions says (over the nominal
//          scan period given here, as the bag reader has no bag times).
// Skips are counted in stats() (read_stats.h). ROS headers stay in src/io.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/io/read_stats.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io {

/// A ROS1 message type as a publisher advertises it.
struct RosMessageType {
  std::string datatype;    // e.g. "sensor_msgs/Imu"
  std::string md5sum;
  std::string definition;  // full definition text (with the MSG: sections)
};

/// The LiDAR message type of a ROS datatype name ("sensor_msgs/PointCloud2",
/// "livox_ros_driver/CustomMsg", "livox_ros_driver2/CustomMsg"); false when
/// unsupported.
bool LidarMessageTypeFromDatatype(const std::string& datatype, LidarMessageType* type);

/// The MD5 sum our decoders expect for `datatype` ("" when unsupported).
std::string ExpectedMd5(const std::string& datatype);

/// Stateful (per-stream stamp order); one thread at a time per stream: the
/// IMU and LiDAR calls may come from two threads.
class SensorMessageDecoder {
 public:
  /// `options`: point time unit, field and reconstruction as for a bag;
  /// `scan_period_s` [s]: the LiDAR's nominal period (azimuth time).
  SensorMessageDecoder(const BagReaderOptions& options, double scan_period_s);

  /// Decodes one sensor_msgs/Imu. Ok with *accepted = false: skipped and
  /// counted. A malformed message is an error (DataLoss).
  Status DecodeImu(const uint8_t* data, size_t size, ImuSample* imu, bool* accepted);
  /// Decodes one LiDAR message of `type`; as DecodeImu. A PointCloud2 whose
  /// per-point time span cannot be a scan (a wrong unit) is InvalidArgument.
  Status DecodeScan(LidarMessageType type, const uint8_t* data, size_t size, LidarScan* scan,
                    bool* accepted);

  /// Delivered and skipped counts (read after the streams stopped).
  const ReadStats& stats() const { return stats_; }

 private:
  BagReaderOptions options_;
  double scan_period_s_;
  bool has_imu_stamp_ = false;
  int64_t last_imu_stamp_ns_ = 0;
  bool has_scan_stamp_ = false;
  int64_t last_scan_stamp_ns_ = 0;
  ReadStats stats_;
};

/// The ROS serialization of one IMU sample as the bag writer writes it
/// (sensor_msgs/Imu, orientation unknown).
Status SerializeImu(const ImuSample& imu, uint32_t seq, std::vector<uint8_t>* bytes,
                    RosMessageType* type);
/// The ROS serialization of one scan in `options.lidar_format` (with the
/// PointCloud2 time field options), as the bag writer writes it.
Status SerializeScan(const LidarScan& scan, const BagWriterOptions& options, uint32_t seq,
                     std::vector<uint8_t>* bytes, RosMessageType* type);

}  // namespace swarmlio::io
