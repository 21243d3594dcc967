// BackEnd: step 4 of lio::Odometry's scan (Update) and the back end's part
// of step 5 (map insertion), one interface for the iterated ESIKF
// (src/lio/filter_back_end.h) and the fixed-lag window
// (src/window/window_back_end.h). The odometry holds one, chosen at Create
// by OdometryOptions::estimator, and calls it without knowing which.
// Internal (not installed): the odometry owns the map and the propagator a
// back end works on.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/scan_stages.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio::internal {

class BackEnd {
 public:
  virtual ~BackEnd() = default;

  /// The IMU interval from the newest state to the scan end, fed with
  /// exactly what the propagator consumes: StartInterval at the propagator's
  /// time with its last sample, AddImu per sample, IntegrateTo the scan end
  /// (the filter's are no-ops: the propagator is its process model).
  virtual void StartInterval(int64_t stamp_ns,
                             const ImuSample& last_sample,
                             double acceleration_to_m_s2,
                             const EgoState& newest) = 0;
  virtual void AddImu(const ImuSample& sample) = 0;
  virtual void IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample) = 0;

  /// Step 4: scan->x, P in = the prediction, out = the posterior (or the
  /// prediction when not updated); fills scan->out's update fields and
  /// counts updated, degenerate and failed updates in *counters.
  /// `points_in_b`: the scan undistorted to its end (body frame).
  virtual void Update(const UpdateRequest& request,
                      const std::vector<Eigen::Vector3d>& points_in_b,
                      ScanContext* scan,
                      OdometryCounters* counters) = 0;

  /// The back end's part of step 5: the map insertion that belongs to this
  /// scan (the filter: the scan itself; the window inserted the scans that
  /// left it in Update).
  virtual void Commit(const std::vector<Eigen::Vector3d>& points_in_b, ScanContext* scan) = 0;

  /// The end of a log: every scan the back end still holds enters the map.
  virtual void Flush() = 0;
};

/// Registers the points with x, inserts all but the excluded ones and those
/// listed in skip_indices into `map` (moving its box to x) and returns how
/// many were excluded. registered_in_G (cleared) gets every point not
/// excluded.
int InsertScan(const std::vector<Eigen::Vector3d>& points_in_b,
               const EgoState& x,
               const std::vector<ExcludedRegion>& excluded,
               std::vector<Eigen::Vector3d>* registered_in_G,
               const std::vector<int>* skip_indices,
               LocalMap* map);

/// Whether every value of x and P is finite (a posterior a back end keeps).
bool IsFinite(const SwarmState& x, const Eigen::MatrixXd& P);

}  // namespace swarmlio::lio::internal
