#include "swarmlio/lio/odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "odometry_impl.h"
#include "src/lio/filter_back_end.h"
#include "src/window/window_back_end.h"
#include "swarmlio/common/stopwatch.h"
#include "swarmlio/lio/imu_initializer.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/in_flight_alignment.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/preprocess.h"
#include "swarmlio/lio/scan_association.h"
#include "swarmlio/lio/undistortion.h"
#include "swarmlio/math/angles.h"

namespace swarmlio::lio {
namespace {

using Clock = std::chrono::steady_clock;

int64_t ScanEndNs(const LidarScan& scan) {
  double last_s = 0.0;
  for (const LidarPoint& p : scan.points) {
    if (std::isfinite(p.offset_time_s)) last_s = std::max(last_s, p.offset_time_s);
  }
  return scan.stamp_ns + static_cast<int64_t>(std::llround(last_s * 1e9));
}

}  // namespace

Status Odometry::Create(const OdometryOptions& options,
                        const LidarOptions& lidar,
                        std::unique_ptr<Odometry>* odometry) {
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("odometry options: " + invalid);
  }
  if (const std::string invalid = lidar.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("lidar options: " + invalid);
  }
  std::unique_ptr<Odometry> out(new Odometry(options, lidar));
  SWARMLIO_RETURN_IF_ERROR(ImuInitializer::Create(options.imu_init, &out->impl_->initializer));
  SWARMLIO_RETURN_IF_ERROR(ImuPropagator::Create(options.propagation, &out->impl_->propagator));
  out->impl_->preprocess = std::make_unique<Preprocess>(
      options.preprocess, lidar.QuaternionImuLidar().toRotationMatrix(), lidar.p_lidar_in_imu_m);
  SWARMLIO_RETURN_IF_ERROR(out->CreateBackEnd());
  *odometry = std::move(out);
  return Status::Ok();
}

Status Odometry::CreateBackEnd() {
  Impl& im = *impl_;
  if (options_.estimator == EstimatorKind::kWindow) {
    return window::WindowBackEnd::Create(options_, &im.map, im.propagator.get(), &im.parallel,
                                         &im.back_end);
  }
  im.back_end = std::make_unique<internal::FilterBackEnd>(options_, &im.map, im.propagator.get(),
                                                          &im.parallel);
  return Status::Ok();
}

Odometry::Odometry(const OdometryOptions& options, const LidarOptions& lidar)
    : options_(options), lidar_(lidar), impl_(std::make_unique<Impl>(options)) {}

Odometry::~Odometry() = default;

bool Odometry::initialized() const { return impl_->initialized && !impl_->probe.active; }
const ImuInitialization& Odometry::initialization() const { return impl_->initialization; }
const SwarmState& Odometry::state() const { return impl_->propagator->state(); }
const Eigen::MatrixXd& Odometry::covariance() const { return impl_->propagator->covariance(); }
std::vector<Eigen::Vector3d> Odometry::MapPoints() const { return impl_->map.Points(); }
size_t Odometry::map_size() const { return impl_->map.size(); }
size_t Odometry::MapMemoryBytes() const { return impl_->map.MemoryBytes(); }

Status Odometry::AddImu(const ImuSample& raw) {
  ++counters_.imu_samples;
  ImuSample sample = raw;
  sample.stamp_ns -= static_cast<int64_t>(std::llround(options_.imu_time_offset_s * 1e9));
  if (!sample.angular_velocity_rad_s.allFinite() || !sample.linear_acceleration.allFinite()) {
    ++counters_.imu_rejected;
    return Status::InvalidArgument("IMU sample at " + std::to_string(raw.stamp_ns) +
                                   " ns has non-finite values; dropped");
  }
  const Status in_order = impl_->input.AddImuStamp(sample.stamp_ns, raw.stamp_ns);
  if (!in_order.ok()) {
    ++counters_.imu_out_of_order;
    return in_order;
  }
  if (!impl_->initialized) {
    SWARMLIO_RETURN_IF_ERROR(impl_->initializer->AddSample(sample));
    if (!impl_->initializer->WindowFull()) {
      init_error_ = "IMU window not full yet (" +
                    std::to_string(impl_->initializer->num_samples_in_window()) + " samples)";
      return Status::Ok();
    }
    ImuInitialization init;
    const bool in_flight = options_.initialization == InitializationMode::kInFlight;
    ImuInitializer::InFlightCoarseSigmas coarse;
    coarse.velocity_m_s = options_.in_flight.coarse_velocity_stddev_m_s;
    coarse.gravity_m_s2 = options_.in_flight.coarse_gravity_stddev_m_s2;
    coarse.gyro_bias_rad_s = options_.in_flight.gyro_bias_stddev_rad_s;
    const Status status = in_flight ? impl_->initializer->InitializeInFlight(coarse, &init)
                                    : impl_->initializer->Initialize(&init);
    if (!status.ok()) {
      init_error_ = status.message();
      return Status::Ok();  // keep sliding the window
    }
    SWARMLIO_RETURN_IF_ERROR(impl_->propagator->Reset(init));
    impl_->initialization = init;
    impl_->initialized = true;
    if (in_flight) {
      StartInFlightProbe(init);
      return Status::Ok();
    }
    init_error_.clear();
    impl_->seed_pending = true;  // seeded before the first scan is processed
    impl_->seed_window_start_ns = impl_->initializer->window_start_ns();
    return Status::Ok();
  }
  impl_->imu_queue.push_back(sample);
  if (impl_->probe.active) impl_->probe.imu.push_back(sample);
  return Status::Ok();
}

Status Odometry::AddScan(const LidarScan& scan) {
  ++counters_.scans;
  if (scan.points.empty()) {
    ++counters_.scans_empty;
    return Status::InvalidArgument("scan at " + std::to_string(scan.stamp_ns) +
                                   " ns has no points; dropped");
  }
  const int64_t end_ns = ScanEndNs(scan);
  if (!impl_->initialized || scan.stamp_ns < impl_->initialization.stamp_ns) {
    ++counters_.scans_before_init;
    if ((!impl_->initialized || impl_->seed_pending) && options_.seed_map_from_static_start) {
      // Kept while it may still lie in the initialization window.
      auto& kept = impl_->static_start_scans;
      kept.push_back({scan, end_ns});
      const int64_t window_start_ns = impl_->initializer->window_start_ns();
      while (!kept.empty() && kept.front().scan.stamp_ns < window_start_ns) kept.pop_front();
      while (static_cast<int>(kept.size()) > options_.max_queued_scans) kept.pop_front();
    }
    return Status::Ok();  // expected during the static start: not an error
  }
  const Status queued = impl_->input.AddScan({scan, end_ns});
  if (queued.code() == Status::Code::kInvalidArgument) {
    ++counters_.scans_out_of_order;
    return queued;
  }
  if (impl_->probe.active) impl_->probe.scans.push_back({scan, end_ns});
  if (queued.code() == Status::Code::kOutOfRange) ++counters_.scans_dropped_queue;
  return queued;
}

void Odometry::SeedMapFromStaticStart(int64_t window_start_ns) {
  Impl& im = *impl_;
  im.seed_pending = false;
  // The window passed the static test, so a scan wholly inside it was taken
  // at the initial pose: R_G_b = I, p_b_in_G = 0 (G is the IMU frame at the
  // window's end), without motion distortion.
  std::vector<Eigen::Vector3d> points_in_G;
  std::vector<double> ranges;  // observation ranges (from the body origin)
  for (const PendingScan& pending : im.static_start_scans) {
    if (pending.scan.stamp_ns < window_start_ns || pending.end_ns > im.initialization.stamp_ns) {
      continue;
    }
    im.preprocess->Run(pending.scan, &im.points_in_b);
    if (static_cast<int>(im.points_in_b.size()) < options_.min_scan_points) continue;
    for (const PointXYZT& p : im.points_in_b) {
      points_in_G.push_back(p.p_in_b);
      ranges.push_back(p.p_in_b.norm());
    }
    ++counters_.scans_seeding_map;
  }
  im.static_start_scans.clear();
  if (points_in_G.empty()) return;
  im.map.UpdateCenter(Eigen::Vector3d::Zero());
  im.map.Insert(points_in_G, &ranges);
}

void Odometry::FinishLog() {
  if (impl_->seed_pending) SeedMapFromStaticStart(impl_->seed_window_start_ns);
  impl_->back_end->Flush();
}

Status Odometry::ProcessReadyScans(bool flush, std::vector<ScanOutput>* outputs) {
  Status first_error;
  ScanContext& scan = impl_->probe_scan;
  while (NextScan(flush, &scan)) {
    Status status = scan.status;
    if (scan.predicted) {
      Update(UpdateRequest(), &scan);
      outputs->emplace_back();
      status = Commit(&scan, &outputs->back());
    }
    if (!status.ok() && first_error.ok()) first_error = status;
  }
  if (flush) FinishLog();
  return first_error;
}

bool Odometry::NextScan(bool flush, ScanContext* scan) {
  Impl& im = *impl_;
  PendingScan pending;
  while (im.input.PopReady(flush, &pending)) {
    if (im.seed_pending) SeedMapFromStaticStart(im.seed_window_start_ns);
    scan->raw = std::move(pending.scan);
    scan->end_ns = pending.end_ns;
    scan->flush = flush;
    Predict(scan);
    if (!im.probe.active) return true;
    // An in-flight pass: no front end, no output.
    ProcessProbeScan(scan);
    const bool pass_over =
        im.probe.active &&
        scan->end_ns - im.probe.start.stamp_ns >=
            static_cast<int64_t>(std::llround(options_.in_flight.probe_duration_s * 1e9));
    if (pass_over) FinishInFlightPass();  // restarts from t0 (queues refilled) or abandons
    if (!scan->status.ok()) {
      scan->predicted = false;  // the error reaches the caller; the scan is done
      return true;
    }
  }
  return false;
}

void Odometry::ProcessProbeScan(ScanContext* scan) {
  if (!scan->predicted) return;
  Update(UpdateRequest(), scan);
  ScanOutput out;
  scan->status = Commit(scan, &out);
  if (out.updated) {
    impl_->probe.positions.push_back({out.stamp_ns, out.state.p_b_in_G, out.state.q_G_b});
    impl_->probe.gyro_bias = out.state.gyro_bias;
  }
}

void Odometry::Predict(ScanContext* scan) {
  Impl& im = *impl_;
  scan->started = Clock::now();
  scan->predicted = false;
  scan->status = Status::Ok();
  scan->excluded.clear();
  ScanOutput& out = scan->out;
  out = ScanOutput();
  out.scan_stamp_ns = scan->raw.stamp_ns;
  const int64_t end_ns = scan->end_ns;
  // In flight, the odometry proper starts at started_ns (the newest input when
  // the last pass ended); at rest started_ns is the initialization's stamp.
  out.held_by_initialization = im.initialization.started_ns > im.initialization.stamp_ns &&
                               end_ns <= im.initialization.started_ns;
  out.num_raw_points = static_cast<int>(scan->raw.points.size());

  // 1. Preprocess.
  Clock::time_point t = Clock::now();
  im.preprocess->Run(scan->raw, &im.points_in_b);
  out.num_points = static_cast<int>(im.points_in_b.size());
  out.timings.preprocess_s = SecondsSince(t);

  // 2. Propagate over the scan's IMU samples to its end.
  t = Clock::now();
  if (!Propagate(scan)) return;
  out.timings.propagate_s = SecondsSince(t);

  // 3. Motion compensation to the scan end.
  t = Clock::now();
  const ImuPropagator& prop = *im.propagator;
  if (Status status =
          UndistortPoints(im.points_in_b, scan->raw.stamp_ns, prop.scan_poses(), &im.undistorted);
      !status.ok()) {
    scan->status = status;
    return;
  }
  out.timings.undistort_s = SecondsSince(t);
  scan->stamp_ns = prop.stamp_ns();
  scan->poses = &prop.scan_poses();
  scan->previous_scan_degenerate = im.previous_degenerate;
  scan->x = prop.state();
  scan->P = prop.covariance();
  scan->predicted = true;
}

bool Odometry::Propagate(ScanContext* scan) {
  Impl& im = *impl_;
  const int64_t end_ns = scan->end_ns;
  ImuPropagator& prop = *im.propagator;
  if (end_ns < prop.stamp_ns()) {
    ++counters_.scans_out_of_order;
    scan->status = Status::InvalidArgument("scan ending at " + std::to_string(end_ns) +
                                           " ns ends before the current state time; dropped");
    return false;
  }
  prop.StartScan();
  // The back end's IMU interval (the window's factor) gets exactly what the
  // propagator consumes.
  im.back_end->StartInterval(prop.stamp_ns(), prop.last_sample(),
                             im.initialization.acceleration_to_m_s2, prop.state().ego);
  while (!im.imu_queue.empty() && im.imu_queue.front().stamp_ns <= end_ns) {
    const ImuSample sample = im.imu_queue.front();
    im.imu_queue.pop_front();
    im.back_end->AddImu(sample);
    Status status = prop.AddImu(sample);
    if (status.code() == Status::Code::kOutOfRange) {
      // A gap in the IMU stream: hold the state and restart from this sample.
      ++counters_.imu_gaps;
      const SwarmState x = prop.state();
      const Eigen::MatrixXd P = prop.covariance();
      if (Status reset = prop.Reset(x, P, sample, im.initialization.acceleration_to_m_s2);
          !reset.ok()) {
        scan->status = reset;
        return false;
      }
      if (scan->status.ok()) scan->status = status;
    } else if (!status.ok() && scan->status.ok()) {
      scan->status = status;
    }
  }
  const ImuSample* next = im.imu_queue.empty() ? nullptr : &im.imu_queue.front();
  im.back_end->IntegrateTo(end_ns, next);
  if (Status status = prop.PropagateTo(end_ns, next); !status.ok()) {
    // Flushing past the end of the IMU data: hold the state at its last time.
    if (!scan->flush || status.code() != Status::Code::kOutOfRange) {
      scan->status = status;
      return false;
    }
  }
  return true;
}

void Odometry::Update(const UpdateRequest& request, ScanContext* scan) {
  Impl& im = *impl_;
  // The front end may have changed the teammate blocks.
  if (scan->x.layout() != im.propagator->state().layout())
    im.propagator->SetState(scan->x, scan->P);
  im.back_end->Update(request, im.undistorted, scan, &counters_);
  if (scan->out.updated) im.previous_degenerate = scan->out.degenerate;
}

Eigen::Matrix3d Odometry::PositionCovarianceInG(const ScanOutput& out) {
  Impl& im = *impl_;
  const Eigen::Matrix3d R_G_b = out.state.q_G_b.normalized().toRotationMatrix();
  if (!im.have_anchor && out.map_size > 0) {
    im.anchor.R_G_b0 = R_G_b;
    im.anchor.p_lidar0_in_G = out.state.p_b_in_G + R_G_b * lidar_.p_lidar_in_imu_m;
    im.anchor.p_lidar_in_imu_m = lidar_.p_lidar_in_imu_m;
    im.have_anchor = true;
  }
  constexpr int kP = ErrorStateLayout::kPosition.offset;
  Eigen::Matrix3d cov = out.covariance.block<3, 3>(kP, kP);
  if (im.have_anchor) {
    CalibrationUncertainty calibration;
    calibration.rotation_sigma_rad = lidar_.calibration_rotation_sigma_deg * kRadiansPerDegree;
    calibration.translation_sigma_m = lidar_.calibration_translation_sigma_m;
    cov += CalibrationGaugeCovariance(calibration, im.anchor, R_G_b, out.state.p_b_in_G);
  }
  return cov;
}

Status Odometry::Commit(ScanContext* scan, ScanOutput* output) {
  Impl& im = *impl_;
  ScanOutput& out = scan->out;
  // 5. Map (the back end's part: the filter inserts this scan).
  im.back_end->Commit(im.undistorted, scan);
  out.map_size = im.map.size();
  out.stamp_ns = im.propagator->stamp_ns();
  out.state = scan->x.ego;
  out.covariance = scan->P.topLeftCorner<ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim>();
  out.position_covariance_in_G = PositionCovarianceInG(out);
  out.timings.total_s = SecondsSince(scan->started);
  im.input.MarkProcessed(scan->end_ns);
  ++counters_.scans_processed;
  *output = std::move(out);
  return scan->status;
}

}  // namespace swarmlio::lio
