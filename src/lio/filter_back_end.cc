#include "src/lio/filter_back_end.h"

#include "swarmlio/common/stopwatch.h"

#include <chrono>

namespace swarmlio::lio::internal {
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

FilterBackEnd::FilterBackEnd(const OdometryOptions& options, LocalMap* map,
                             ImuPropagator* propagator, const ParallelFor* parallel)
    : options_(options),
      map_(map),
      propagator_(propagator),
      associator_(map, options.association, parallel),
      update_(options.update) {}

void FilterBackEnd::Update(const UpdateRequest& request,
                           const std::vector<Eigen::Vector3d>& points_in_b, ScanContext* scan,
                           OdometryCounters* counters) {
  SwarmState& x = scan->x;
  Eigen::MatrixXd& P = scan->P;
  ScanOutput* out = &scan->out;
  const bool map_ready = !map_->empty();
  map_was_empty_ = !map_ready;
  const bool enough_points = static_cast<int>(points_in_b.size()) >= options_.min_scan_points;
  if (!map_ready || !enough_points) return;
  associator_.Reset(&points_in_b);
  PlaneMeasurementModel planes(
      [&](const SwarmState& at, std::vector<PlaneCorrespondence>* correspondences) {
        return associator_.Associate(at, correspondences);
      });
  std::vector<MeasurementModel*> models{&planes};
  models.insert(models.end(), request.models.begin(), request.models.end());
  const bool subset = request.select_teammates;
  const EsikfUpdateResult result =
      update_.Run(x, P, models, subset ? &request.estimated_teammates : nullptr,
                  subset ? &request.considered_teammates : nullptr, propagator_->stamp_ns());
  out->timings.association_s = result.association_time_s;
  out->timings.solve_s = result.solve_time_s;
  out->timings.covariance_s = result.covariance_time_s;
  out->iterations = result.iterations;
  out->converged = result.converged;
  out->num_correspondences = static_cast<int>(planes.correspondences().size());
  out->num_measurement_blocks = result.num_residual_blocks;
  out->min_normal_information = associator_.stats().MinNormalInformation();
  out->degenerate = out->min_normal_information < options_.association.degeneracy_threshold;
  if (result.status.ok() && IsFinite(result.state, result.covariance)) {
    x = result.state;
    P = result.covariance;
    out->updated = true;
    ++counters->scans_updated;
    if (out->degenerate) ++counters->scans_degenerate;
    propagator_->SetState(x, P);
  } else {
    ++counters->updates_failed;
    out->update_error = result.status.ok() ? "non-finite posterior" : result.status.message();
  }
}

void FilterBackEnd::Commit(const std::vector<Eigen::Vector3d>& points_in_b, ScanContext* scan) {
  // Map: register with the (posterior) state and insert, except the points
  // in the excluded regions (teammates). Only updated scans and the very
  // first one grow the map, so a failed update cannot write a misregistered
  // scan into it.
  ScanOutput& out = scan->out;
  const Clock::time_point t = Clock::now();
  if (out.updated || map_was_empty_) {
    // Without insert_matched_points, the points the update matched to a map
    // plane stay out of the map (the map explains them already).
    const std::vector<int>* matched = options_.insert_matched_points || !out.updated
                                          ? nullptr
                                          : &associator_.matched_point_indices();
    out.num_excluded_points =
        InsertScan(points_in_b, scan->x.ego, scan->excluded,
                   options_.output_registered_scan ? &out.registered_in_G : nullptr, matched,
                   map_);
  }
  out.timings.map_update_s = SecondsSince(t);
}

}  // namespace swarmlio::lio::internal
