// ScanStageHooks: the stages of lio::Odometry's scan pipeline that a
// composing component (swarm::DroneEstimator) takes part in, so that the
// odometry stays single-drone and the swarm layer stays out of it:
//
//   front end   after propagation to the scan end: the raw scan and the IMU
//               poses over it (to undistort it at full resolution with
//               reflectivity, for teammate detection), the predicted state,
//               which the hook may change (add / remove teammate blocks);
//               the hook returns extra measurement models for the update,
//               the teammate blocks the update estimates, and regions of the
//               scan (teammates) kept out of the map;
//   update      prior + point-to-plane + the hook's models (EsikfUpdate);
//   removal     points inside the excluded regions are not inserted;
//   map         insertion of the rest;
//   after       the hook sees the scan's output and posterior.
//
// Hooks run inside Odometry::AddImu / AddScan / Flush, on the caller's thread.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/measurement_model.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

struct ScanOutput;

/// What the front end sees of one scan.
struct FrontEndScan {
  const LidarScan* raw = nullptr;              // LiDAR frame, as received
  int64_t end_stamp_ns = 0;                    // the state time (scan end)
  const std::vector<ImuPose>* poses = nullptr;  // propagated poses over the scan (undistortion)
  bool previous_scan_degenerate = false;       // the last updated scan's degeneracy flag
};

/// A ball in the body frame at the scan end whose points stay out of the map.
struct ExcludedRegion {
  Eigen::Vector3d center_in_b = Eigen::Vector3d::Zero();  // [m]
  double radius_m = 0.0;
};

/// What the front end asks of the update.
struct UpdateRequest {
  std::vector<MeasurementModel*> models;  // owned by the hook, valid until OnUpdated
  /// Teammate blocks the update estimates (the others: Schmidt "consider").
  std::vector<int> estimated_teammates;
  /// Teammate blocks the models' residuals name that the update does not
  /// correct (EsikfUpdate::Run, "considered teammates").
  std::vector<int> considered_teammates;
  std::vector<ExcludedRegion> excluded;
};

class ScanStageHooks {
 public:
  virtual ~ScanStageHooks() = default;
  /// `x`, `P`: the prediction at the scan end; the hook may add or remove
  /// teammate blocks (layout and covariance together). An error skips the
  /// hook's part of this scan (the odometry still updates from the LiDAR).
  virtual Status OnFrontEnd(const FrontEndScan& scan, SwarmState* x, Eigen::MatrixXd* P,
                            UpdateRequest* request) = 0;
  /// After the map insertion: the scan's output and the posterior.
  virtual void OnScanDone(const ScanOutput& output, const SwarmState& x,
                          const Eigen::MatrixXd& P) = 0;
};

}  // namespace swarmlio::lio
