// Writes one drone's simulated records: a ROS1 bag or an MCAP file of ROS 2
// messages (io::BagWriterOptions::format; IMU, LiDAR, ground truth)
// and a TUM trajectory file (timestamp tx ty tz qx qy qz qw) of T_Gi_b; and
// the run's resolved scenario (with the truth of every drawn imperfection)
// and replay manifest (with the calibration handed to the estimator).
#pragma once

#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/io/bag_writer.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {

/// `base` with the LiDAR message type and per-point time unit of `lidar`
/// (its message_format and timestamp_unit): a drone's bag is written the way
/// its sensor description says the driver publishes.
io::BagWriterOptions BagOptionsFor(const io::BagWriterOptions& base, const LidarOptions& lidar);

/// The bag file name of drone `name`: "<name>.mcap" when `options.format` is
/// MCAP, else "<name>.bag" (ROS1; also for format auto).
std::string BagFileName(const std::string& name, const io::BagWriterOptions& options);

/// resolved_scenario.yaml: the run settings, each drone's T_W_Gi, sensors
/// and imperfection settings as simulated, and a `truth:` block per drone
/// (true extrinsic, IMU time offset, clock offset and drift, IMU scale /
/// misalignment matrices and vibration phases) next to the calibration the
/// estimator was given. For people and evaluation scripts; nothing reads it.
std::string ResolvedScenarioYaml(const Scenario& scenario, const Simulator& simulator);

/// swarm.yaml, the replay manifest (docs/replay.md): bags, ground truth, and
/// each drone's sensors with the calibration handed to the estimator
/// (GivenCalibration: the truth unless the scenario simulates a calibration
/// error).
std::string ReplayManifestYaml(const Scenario& scenario, const Simulator& simulator);

class DroneOutputWriter : public DroneSink {
 public:
  static Status Open(const std::string& bag_path, const std::string& tum_path,
                     const io::BagWriterOptions& options,
                     std::unique_ptr<DroneOutputWriter>* writer);

  Status OnImu(const ImuSample& imu) override;
  Status OnScan(const LidarScan& scan, int64_t record_time_ns) override;
  Status OnGroundTruth(const PoseStamped& pose) override;
  /// Also writes the teammate-returns truth to `csv_path` (docs/simulator.md
  /// "Outputs"): `scan_stamp_s,scan_end_s,teammate,returns`, one row per
  /// teammate a scan hit; `drone_names[k]` names drone k.
  Status WriteTeammateReturnsTo(const std::string& csv_path, std::vector<std::string> drone_names);
  Status OnTeammateReturns(int64_t scan_stamp_ns, int64_t scan_end_ns,
                           const std::vector<int>& returns_per_drone) override;
  Status Close();

 private:
  DroneOutputWriter() = default;
  std::unique_ptr<io::BagWriter> bag_;
  std::ofstream tum_;
  std::string tum_path_;
  std::ofstream returns_;
  std::string returns_path_;
  std::vector<std::string> drone_names_;
};

}  // namespace swarmlio::sim
