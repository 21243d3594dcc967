// Writes one drone's simulated records: a ROS1 bag (IMU, LiDAR, ground truth)
// and a TUM trajectory file (timestamp tx ty tz qx qy qz qw) of T_Gi_b.
#pragma once

#include <fstream>
#include <memory>
#include <string>

#include "swarmlio/io/bag_writer.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {

/// `base` with the LiDAR message type and per-point time unit of `lidar`
/// (its message_format and timestamp_unit): a drone's bag is written the way
/// its sensor description says the driver publishes.
io::BagWriterOptions BagOptionsFor(const io::BagWriterOptions& base, const LidarOptions& lidar);

class DroneOutputWriter : public DroneSink {
 public:
  static Status Open(const std::string& bag_path, const std::string& tum_path,
                     const io::BagWriterOptions& options,
                     std::unique_ptr<DroneOutputWriter>* writer);

  Status OnImu(const ImuSample& imu) override;
  Status OnScan(const LidarScan& scan, int64_t record_time_ns) override;
  Status OnGroundTruth(const PoseStamped& pose) override;
  Status Close();

 private:
  DroneOutputWriter() = default;
  std::unique_ptr<io::BagWriter> bag_;
  std::ofstream tum_;
  std::string tum_path_;
};

}  // namespace swarmlio::sim
