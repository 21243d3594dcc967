// WindowBackEnd: the fixed-lag window back end of lio::Odometry
// (docs/window.md) on the WindowSmoother: the scan's state joins the window,
// the states beyond K leave it marginalized and enter the map at their
// final estimates, then the window is solved. The IMU interval between two
// states is preintegrated from exactly the samples the propagator consumes.
#pragma once

#include <memory>
#include <vector>

#include "src/lio/back_end.h"
#include "src/window/window_smoother.h"
#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/odometry_options.h"
#include "swarmlio/lio/parallel_for.h"

namespace swarmlio::window {

class WindowBackEnd final : public lio::internal::BackEnd {
 public:
  /// InvalidArgument when the window options do not validate. `map`,
  /// `propagator` and `parallel` (may be null: one thread; the scans'
  /// association) must outlive the back end.
  static Status Create(const lio::OdometryOptions& options,
                       lio::LocalMap* map,
                       lio::ImuPropagator* propagator,
                       const lio::ParallelFor* parallel,
                       std::unique_ptr<lio::internal::BackEnd>* back_end);

  void StartInterval(int64_t stamp_ns,
                     const ImuSample& last_sample,
                     double acceleration_to_m_s2,
                     const EgoState& newest) override;
  void AddImu(const ImuSample& sample) override;
  void IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample) override;

  void Update(const lio::UpdateRequest& request,
              const std::vector<Eigen::Vector3d>& points_in_b,
              lio::ScanContext* scan,
              lio::OdometryCounters* counters) override;
  void Commit(const std::vector<Eigen::Vector3d>&, lio::ScanContext*) override {}
  void Flush() override;

 private:
  WindowBackEnd(const lio::OdometryOptions& options,
                lio::LocalMap* map,
                lio::ImuPropagator* propagator);
  // The scans that left the window, at their final estimates (only scans
  // that a solve updated; docs/window.md "Map").
  void InsertLeaving(const std::vector<LeavingScan>& leaving);
  // The window's solution into the scan's state and output.
  void TakeSolution(const WindowSolveResult& result,
                    bool enough_points,
                    lio::ScanContext* scan,
                    lio::OdometryCounters* counters);

  lio::OdometryOptions options_;
  lio::LocalMap* map_;
  lio::ImuPropagator* propagator_;
  std::unique_ptr<WindowSmoother> window_;
};

}  // namespace swarmlio::window
