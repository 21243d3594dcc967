// The swarm simulator: runs every drone's IMU and LiDAR over a shared world
// (static scene + all drones' bodies + moving decoys) and streams the records
// to one sink per drone. Drones run in parallel (one task per drone); each
// drone has its own random streams derived from the seed, so the output does
// not depend on thread scheduling.
//
// Time: the true time t starts at 0. Drone i's clock stamps an event at true
// time t as stamp_origin_s + t * (1 + clock_drift_ppm * 1e-6) + clock_offset_s
// (IMU samples additionally + imu.time_offset_s and their stamp jitter).
// Global frame G_i = drone i's IMU frame at t = 0.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/sim/drone_body.h"
#include "swarmlio/sim/imperfections.h"
#include "swarmlio/sim/imu_model.h"
#include "swarmlio/sim/lidar_model.h"
#include "swarmlio/sim/random.h"
#include "swarmlio/sim/scene.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

struct DroneConfig {
  std::string name;
  Trajectory trajectory;  // body (IMU) frame in W
  SimulatedLidarOptions lidar;
  SimulatedImuOptions imu;
  DroneBodyOptions body;
  double clock_offset_s = 0.0;   // drone clock - true time at t = 0 [s]
  double clock_drift_ppm = 0.0;  // drone clock rate - 1 [ppm] (truth)
  /// Error of the calibration the estimator is given (swarm.yaml); zero =
  /// the truth. Not used by the simulation itself.
  CalibrationError calibration_error;
};

/// The true LiDAR-IMU calibration of a drone (its sensors as simulated).
SensorCalibration TrueCalibration(const DroneConfig& drone);
/// The calibration handed to the estimator: the truth with calibration_error.
SensorCalibration GivenCalibration(const DroneConfig& drone);
/// The drone's LiDAR as the estimator is told it (swarm.yaml's `lidar:`): the
/// simulated sensor with the given extrinsic (GivenCalibration), never the truth.
LidarOptions GivenLidarOptions(const DroneConfig& drone);

struct MovingObjectConfig {
  std::string name;
  Trajectory trajectory;
  std::vector<Primitive> parts_b;
};

struct SimulationConfig {
  double duration_s = 60.0;
  uint64_t seed = 1;
  double stamp_origin_s = 1000.0;       // true time 0 in every clock [s]
  double ground_truth_rate_hz = 100.0;
  int num_threads = 2;
};

/// Receives one drone's records in time order. Called from that drone's
/// worker thread only.
class DroneSink {
 public:
  virtual ~DroneSink() = default;
  virtual Status OnImu(const ImuSample& imu) = 0;
  /// `record_time_ns`: the drone-clock time the frame was complete.
  virtual Status OnScan(const LidarScan& scan, int64_t record_time_ns) = 0;
  /// Ground truth T_Gi_b in the drone's global frame, stamped in its clock.
  virtual Status OnGroundTruth(const PoseStamped& pose) = 0;
  /// Truth for evaluation, after OnScan of a scan that sees a teammate: how
  /// many of its returns hit each drone's body (`returns_per_drone[k]`: drone
  /// k, 0 for the own entry). The scan's first point is stamped
  /// `scan_stamp_ns`, its last `scan_end_ns` (drone clock). Default: ignored.
  virtual Status OnTeammateReturns(int64_t /*scan_stamp_ns*/, int64_t /*scan_end_ns*/,
                                   const std::vector<int>& /*returns_per_drone*/) {
    return Status::Ok();
  }
};

struct DroneStats {
  int64_t imu_samples = 0;
  int64_t scans = 0;
  int64_t points = 0;
  int64_t points_on_teammates = 0;   // returns from other drones' bodies
  int64_t tape_points = 0;           // returns above 150 (the Livox retro-reflective range)
  int64_t scans_seeing_teammates = 0;
};

class Simulator {
 public:
  Simulator(Scene scene, std::vector<DroneConfig> drones, std::vector<MovingObjectConfig> objects,
            const SimulationConfig& config);
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const SimulationConfig& config() const { return config_; }
  const std::vector<DroneConfig>& drones() const { return drones_; }
  const Scene& scene() const { return scene_; }
  /// All moving objects: drones first (index = drone index), then the others.
  const std::vector<MovingObject>& moving_objects() const { return objects_; }

  /// Drone i's global frame G_i in W (its IMU pose at t = 0).
  Pose T_W_G(int drone) const;
  /// Drone-clock stamp of true time t.
  int64_t StampNs(int drone, double t) const;
  /// Drone i's IMU scale/misalignment and vibration phases (truth).
  ImuErrors ImuErrorsOf(int drone) const;

  /// Simulates every drone; sinks[i] receives drone i. Returns the first error.
  Status Run(const std::vector<DroneSink*>& sinks, std::vector<DroneStats>* stats) const;
  /// Simulates one drone (thread-safe: const, own random streams).
  Status RunDrone(int drone, DroneSink* sink, DroneStats* stats) const;

 private:
  Scene scene_;
  std::vector<DroneConfig> drones_;
  std::vector<MovingObjectConfig> extra_objects_;
  std::vector<MovingObject> objects_;
  SimulationConfig config_;
};

}  // namespace swarmlio::sim
