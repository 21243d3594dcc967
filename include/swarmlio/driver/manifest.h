// SwarmManifest: which logs make up one swarm run, one entry per drone
// (docs/replay.md). The simulator writes one (swarm.yaml) next to its bags;
// for recorded flights the user writes it by hand:
//
//   name: lab_flight_3
//   drones:
//     - name: uav1
//       bag: uav1.bag                   # relative to this file's folder
//       ground_truth: uav1_gt_tum.txt   # optional TUM file (else the bag's topic, if any)
//       ground_truth_frame: auto        # G | other | auto (default): frame of the ground truth
//       sensor_preset: ../configs/livox_mid360.yaml   # lidar: + imu: sections
//       lidar: {p_lidar_in_imu_m: [0, 0, 0.08]}        # optional overrides
//       bag_topics: {imu_topic: /mavros/imu/data}
//       odometry: {imu_time_offset_s: 0.002}
//       p_G_in_W_m: [0, 0, 0]           # optional, for plots: G in a common frame W
//       q_W_G_xyzw: [0, 0, 0, 1]
//       start_offset_s: 0               # optional: start this far into the log [s]
//       restart_at_s: 0                 # optional: killed and restarted this far in [s]
//
// Odometry defaults follow the drone's LiDAR (lio::OdometryOptionsFor), then
// the `odometry:` keys apply over them; the IMU initializer takes the
// acceleration unit of the `imu:` section.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/consistency.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/lio/odometry_options.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/airframe.h"
#include "swarmlio/teammate/teammate_detector_options.h"

namespace swarmlio::driver {

/// How a drone's clock relates to the true time of a simulated run (YAML
/// `true_clock:` of a drone entry; the simulator writes it): the drone stamps
/// true time t as origin_s + t (1 + drift_ppm 1e-6) + offset_s. The replay
/// uses it only to deliver packets on one time line; the estimators never see
/// it (they estimate the offsets, swarm.synchronize_clocks). Absent: the
/// drones' clocks agree.
struct TrueClock {
  double offset_s = 0.0;     // drone clock - true time at t = 0 [s]
  double drift_ppm = 0.0;    // drone clock rate - 1 [ppm]
  double origin_s = 1000.0;  // stamp of true time 0 on a drift-free, offset-free clock [s]

  /// Stamp on this clock of the true time `true_ns` (both int64 ns), and back.
  int64_t ToDrone(int64_t true_ns) const;
  int64_t ToTrue(int64_t drone_ns) const;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("offset_s", offset_s, FieldSpec::InRange(-1e6, 1e6, "s", "drone clock - true time at t = 0"));
    v("drift_ppm", drift_ppm, FieldSpec::InRange(-1e4, 1e4, "ppm", "drone clock rate - 1"));
    v("origin_s", origin_s, FieldSpec::InRange(0.0, 1e10, "s", "stamp of true time 0"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

struct DroneInput {
  std::string name;
  std::string bag_path;           // resolved (relative to the manifest folder)
  std::string ground_truth_path;  // resolved TUM file, "" = none
  eval::GroundTruthFrame ground_truth_frame = eval::GroundTruthFrame::kAuto;
  std::string teammate_returns_path;  // resolved simulator truth CSV, "" = none
  LidarOptions lidar;
  ImuOptions imu;
  io::BagReaderOptions bag;
  lio::OdometryOptions odometry;
  teammate::TeammateDetectorOptions teammate;  // YAML `teammate:` of the drone entry
  swarm::SwarmOptions swarm;                   // YAML `swarm:` of the drone entry
  teammate::AirframeDescription airframe;      // YAML `airframe:`: the drone's own body,
                                               // announced to its teammates
  TrueClock true_clock;                        // simulation truth, packet delivery only
  /// The drone starts this long after its log's first record: every record
  /// before is skipped (a late join or a restart mid-flight, as
  /// LiveOptions::start_offset_s) [s]. Its G is then the IMU frame at its
  /// (in-flight) initialization, not at the log's start.
  double start_offset_s = 0.0;
  /// A restart mid-flight (the process killed and started again): at this
  /// time after the log's first record (0 = never) the drone's estimator is
  /// dropped, the drone is down for restart_down_s, then a new estimator
  /// (a new session, odometry.initialization = restart_initialization)
  /// starts from the log there. Outputs: the second session only [s].
  double restart_at_s = 0.0;
  double restart_down_s = 1.0;  // [s]
  lio::InitializationMode restart_initialization = lio::InitializationMode::kInFlight;
  /// Where the drone's global frame G lies in a common world frame W, only
  /// for drawing all drones in one top view (identity when unknown).
  Eigen::Matrix3d R_W_G = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_G_in_W_m = Eigen::Vector3d::Zero();

  /// The same as one transform (a simulated run's true T_Gi_Gj is
  /// T_W_G() of i, inverted, times T_W_G() of j).
  Eigen::Isometry3d T_W_G() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R_W_G;
    T.translation() = p_G_in_W_m;
    return T;
  }
};

struct SwarmManifest {
  std::string name;
  std::vector<DroneInput> drones;
};

/// Odometry defaults for a drone: lio::OdometryOptionsFor(lidar), with the
/// IMU initializer's acceleration unit and gravity reference from `imu`.
lio::OdometryOptions DefaultOdometryOptions(const LidarOptions& lidar, const ImuOptions& imu);

/// Loads and validates a manifest. Errors name file:line: key. Drone names
/// must be unique and non-empty; bags must be given (existence is checked
/// when they are opened).
Status LoadManifest(const std::string& path, SwarmManifest* manifest);
/// Same from YAML text; `name` stands for the file (messages, relative paths).
Status ParseManifest(const std::string& yaml_text, const std::string& name,
                     SwarmManifest* manifest);

/// A manifest for bags given on the command line: every drone uses the same
/// sensor preset (may be ""), names uav1, uav2, ... unless `names` is given.
Status ManifestFromBags(const std::vector<std::string>& bags, const std::string& sensor_preset,
                        const std::vector<std::string>& names, SwarmManifest* manifest);

}  // namespace swarmlio::driver
