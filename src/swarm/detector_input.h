// The points of a scan the teammate detector gets (docs/teammate.md): the raw
// returns at full resolution with reflectivity, of the reflective tape and
// near the trackers of the last scan, motion-compensated to the scan end.
// Internal to src/swarm.
#pragma once

#include <cstdint>
#include <vector>

#include "swarmlio/common/time.h"
#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/undistortion.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/teammate_detector.h"

namespace swarmlio::swarm::internal {

class DetectorInput {
 public:
  DetectorInput(const teammate::TeammateDetectorOptions& detector, const SwarmOptions& swarm,
                const LidarOptions& lidar)
      : detector_(detector), swarm_(swarm), lidar_(lidar) {}

  /// The detector's points of `raw` (t_k: its end, `poses`: propagated over
  /// it), given the predicted state `x` and the trackers of the last
  /// detection (made at last_detection_ns). `min_reflectivity`: the
  /// detector's threshold in force (teammates' airframes may lower it).
  Status Make(const LidarScan& raw, int64_t t_k, const std::vector<lio::ImuPose>& poses,
              const SwarmState& x, const teammate::ScanResult& last_detection,
              int64_t last_detection_ns, double min_reflectivity,
              std::vector<teammate::ScanPoint>* points);

 private:
  // The raw points the detector needs: tape returns and points near the
  // trackers of the last scan (predicted to t_k).
  void Select(const LidarScan& raw, int64_t t_k, const SwarmState& x,
              const teammate::ScanResult& last_detection, int64_t last_detection_ns,
              double min_reflectivity, const Eigen::Matrix3d& R_imu_lidar);

  teammate::TeammateDetectorOptions detector_;
  SwarmOptions swarm_;
  LidarOptions lidar_;
  LidarScan selected_;
  std::vector<lio::UndistortedPoint> undistorted_;
};

}  // namespace swarmlio::swarm::internal
