// FilterBackEnd: the iterated ESIKF back end of lio::Odometry (EsikfUpdate,
// docs/esikf.md): the prediction's prior, the scan's point-to-plane terms
// against the map and the request's models in one update per scan; the
// updated scan (or the very first one) enters the map at Commit.
#pragma once

#include <memory>
#include <vector>

#include "src/lio/back_end.h"
#include "swarmlio/lio/esikf_update.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/odometry_options.h"
#include "swarmlio/lio/parallel_for.h"
#include "swarmlio/lio/scan_association.h"

namespace swarmlio::lio::internal {

class FilterBackEnd final : public BackEnd {
 public:
  /// `map`, `propagator` and `parallel` (may be null: one thread) must
  /// outlive the back end.
  FilterBackEnd(const OdometryOptions& options, LocalMap* map, ImuPropagator* propagator,
                const ParallelFor* parallel = nullptr);

  // The propagator is the filter's process model: no interval of its own.
  void StartInterval(int64_t, const ImuSample&, double, const EgoState&) override {}
  void AddImu(const ImuSample&) override {}
  void IntegrateTo(int64_t, const ImuSample*) override {}

  void Update(const UpdateRequest& request, const std::vector<Eigen::Vector3d>& points_in_b,
              ScanContext* scan, OdometryCounters* counters) override;
  void Commit(const std::vector<Eigen::Vector3d>& points_in_b, ScanContext* scan) override;
  void Flush() override {}

 private:
  OdometryOptions options_;
  LocalMap* map_;
  ImuPropagator* propagator_;
  ScanAssociator associator_;
  EsikfUpdate update_;
  bool map_was_empty_ = false;  // the map before this scan's update
};

}  // namespace swarmlio::lio::internal
