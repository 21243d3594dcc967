// Writer of IMU, LiDAR and ground-truth records to a ROS1 bag (format 2.0),
// readable by the ROS tools (rosbag info/play, rqt_bag) and by BagReader, or
// to an MCAP file of ROS 2 CDR messages (BagWriterOptions::format; by
// default for a ".mcap" path) with the ROS 2 names of the same types.
//
// IMU samples become sensor_msgs/Imu, ground-truth poses
// geometry_msgs/PoseStamped or nav_msgs/Odometry
// (BagWriterOptions::ground_truth_format), scans livox_ros_driver/CustomMsg or
// sensor_msgs/PointCloud2 (BagWriterOptions::lidar_format). See
// docs/bag_format.md for the exact layouts.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io {

class BagWriter {
 public:
  /// Creates (or truncates) the bag at `path`.
  static Status Open(const std::string& path,
                     const BagWriterOptions& options,
                     std::unique_ptr<BagWriter>* writer);

  /// Closes the bag if Close() was not called (errors are then dropped).
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // Each Write* stores the record with bag (receive) time = its stamp, or the
  // given record_time_ns. Stamps must lie in [0, 2^32) s; the bag time 0 is
  // stored as 1 ns because rosbag refuses 0.
  Status WriteImu(const ImuSample& imu);
  Status WriteImu(const ImuSample& imu, int64_t record_time_ns);
  Status WriteScan(const LidarScan& scan);
  Status WriteScan(const LidarScan& scan, int64_t record_time_ns);
  Status WriteGroundTruth(const PoseStamped& pose);
  Status WriteGroundTruth(const PoseStamped& pose, int64_t record_time_ns);

  /// Writes the index and closes the file. Further writes fail.
  Status Close();

  const std::string& path() const;

 private:
  class Impl;
  explicit BagWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::io
