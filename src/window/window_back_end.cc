#include "src/window/window_back_end.h"

#include <chrono>
#include <string>
#include <utility>

#include "swarmlio/common/stopwatch.h"

namespace swarmlio::window {
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

WindowBackEnd::WindowBackEnd(const lio::OdometryOptions& options,
                             lio::LocalMap* map,
                             lio::ImuPropagator* propagator)
    : options_(options), map_(map), propagator_(propagator) {}

Status WindowBackEnd::Create(const lio::OdometryOptions& options,
                             lio::LocalMap* map,
                             lio::ImuPropagator* propagator,
                             const lio::ParallelFor* parallel,
                             std::unique_ptr<lio::internal::BackEnd>* back_end) {
  std::unique_ptr<WindowBackEnd> out(new WindowBackEnd(options, map, propagator));
  SWARMLIO_RETURN_IF_ERROR(WindowSmoother::Create(options.window, options.propagation,
                                                  options.association, options.update, map,
                                                  &out->window_, parallel));
  *back_end = std::move(out);
  return Status::Ok();
}

void WindowBackEnd::StartInterval(int64_t stamp_ns,
                                  const ImuSample& last_sample,
                                  double acceleration_to_m_s2,
                                  const EgoState& newest) {
  window_->StartInterval(stamp_ns, last_sample, acceleration_to_m_s2, newest);
}

void WindowBackEnd::AddImu(const ImuSample& sample) { window_->AddImu(sample); }

void WindowBackEnd::IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample) {
  window_->IntegrateTo(stamp_ns, next_sample);
}

void WindowBackEnd::InsertLeaving(const std::vector<LeavingScan>& leaving) {
  for (const LeavingScan& l : leaving) {
    if (l.insert) {
      lio::internal::InsertScan(l.points_in_b, l.state, l.excluded, nullptr,
                                options_.insert_matched_points ? nullptr : &l.matched, map_);
    }
  }
}

void WindowBackEnd::Update(const lio::UpdateRequest& request,
                           const std::vector<Eigen::Vector3d>& points_in_b,
                           lio::ScanContext* scan,
                           lio::OdometryCounters* counters) {
  SwarmState& x = scan->x;
  lio::ScanOutput* out = &scan->out;
  const bool enough_points = static_cast<int>(points_in_b.size()) >= options_.min_scan_points;

  // The state joins the window; the states beyond K leave it, marginalized.
  WindowStateInput input;
  input.stamp_ns = propagator_->stamp_ns();
  input.x_pred = x;
  input.P_pred = scan->P;
  input.points_in_b = points_in_b;
  input.use_planes = enough_points;
  input.excluded = scan->excluded;
  input.models = request.models;
  input.considered_teammates = request.considered_teammates;
  std::vector<LeavingScan> leaving;
  std::string model_error;
  const Status added =
      window_->AddState(std::move(input), &leaving, &out->timings.marginalize_s, &model_error);
  if (!model_error.empty()) {
    out->front_end_error += (out->front_end_error.empty() ? "" : "; ") + model_error;
  }

  // Map: the scans that left. An empty map is built from the newest scan at
  // its prediction, like the filter's first scan.
  Clock::time_point t = Clock::now();
  InsertLeaving(leaving);
  if (map_->empty()) {
    out->num_excluded_points =
        lio::internal::InsertScan(points_in_b, x.ego, scan->excluded, nullptr, nullptr, map_);
    if (added.ok()) window_->MarkNewestInMap();
  }
  out->timings.map_update_s = SecondsSince(t);
  if (!added.ok()) {
    ++counters->updates_failed;
    out->update_error = added.message();
    return;
  }

  TakeSolution(window_->Solve(), enough_points, scan, counters);
  if (options_.output_registered_scan) {
    const Eigen::Matrix3d R_G_b = x.ego.q_G_b.toRotationMatrix();
    for (const Eigen::Vector3d& p : points_in_b) {
      out->registered_in_G.push_back(R_G_b * p + x.ego.p_b_in_G);
    }
  }
}

void WindowBackEnd::TakeSolution(const WindowSolveResult& result,
                                 bool enough_points,
                                 lio::ScanContext* scan,
                                 lio::OdometryCounters* counters) {
  lio::ScanOutput* out = &scan->out;
  out->timings.build_s = result.build_s;
  out->timings.association_s = result.association_s;
  out->timings.solve_s = result.solve_s;
  out->timings.covariance_s = result.covariance_s;
  out->iterations = result.iterations;
  out->converged = result.converged;
  out->num_correspondences = result.num_correspondences;
  out->num_measurement_blocks = result.num_residual_blocks;
  const bool attempted = result.updated || result.iterations > 0;
  if (attempted && enough_points) {
    out->min_normal_information = result.newest_stats.MinNormalInformation();
    out->degenerate = out->min_normal_information < options_.association.degeneracy_threshold;
  }
  counters->window_restarts = window_->counters().restarts;
  counters->window_reintegrations = window_->counters().reintegrations;
  if (result.status.ok() && lio::internal::IsFinite(result.state, result.covariance)) {
    scan->x = result.state;
    scan->P = result.covariance;
    propagator_->SetState(scan->x, scan->P);
    out->updated = result.updated;
    if (out->updated) {
      ++counters->scans_updated;
      if (out->degenerate) ++counters->scans_degenerate;
    }
  } else if (enough_points) {
    ++counters->updates_failed;
    out->update_error = result.status.ok() ? "non-finite posterior" : result.status.message();
  }
}

void WindowBackEnd::Flush() {
  // The scans still in the window enter the map at their current estimates.
  std::vector<LeavingScan> scans;
  window_->TakeScansForMap(&scans);
  for (const LeavingScan& s : scans) {
    lio::internal::InsertScan(s.points_in_b, s.state, s.excluded, nullptr,
                              options_.insert_matched_points ? nullptr : &s.matched, map_);
  }
}

}  // namespace swarmlio::window
