#include "swarmlio/swarm/drone_estimator.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <utility>

#include "active_observation_updater.h"
#include "broadcaster.h"
#include "detector_input.h"
#include "gravity_updater.h"
#include "message_inbox.h"
#include "observation_gate.h"
#include "passive_observation_updater.h"
#include "scan_report.h"
#include "swarmlio/common/stopwatch.h"
#include "swarmlio/common/time.h"
#include "teammate_registry.h"

namespace swarmlio::swarm {
namespace {}  // namespace

// The collaborators, in construction order (each refers to those above it).
struct DroneEstimator::Parts {
  Parts(int self_id,
        const DroneEstimatorOptions& o,
        const LidarOptions& lidar,
        teammate::TeammateDetector* detector,
        std::unique_ptr<net::ClockSync> sync,
        DroneEstimatorCounters* counters)
      : clock_sync(std::move(sync)),
        registry(self_id, o.swarm, detector),
        active(o.swarm, &registry, &detection.observations, counters),
        passive(o.swarm, &registry, counters),
        gravity(o.swarm, counters),
        broadcaster(self_id, o.swarm, o.airframe, clock_sync.get(), &registry, counters),
        inbox(self_id,
              o.swarm,
              {&registry, &passive, &gravity, &broadcaster, detector, clock_sync.get(), counters}),
        detector_input(o.teammate, o.swarm, lidar) {}

  std::unique_ptr<net::ClockSync> clock_sync;  // null when synchronize_clocks is off
  teammate::ScanResult detection;              // the last scan's
  int64_t last_detection_ns = 0;
  internal::TeammateRegistry registry;
  internal::ObservationGate gate;
  // The updaters, called in this order (a new measurement type: one more here).
  internal::ActiveObservationUpdater active;
  internal::PassiveObservationUpdater passive;
  internal::GravityUpdater gravity;
  std::vector<internal::MeasurementUpdater*> updaters{&active, &passive, &gravity};
  internal::Broadcaster broadcaster;
  internal::MessageInbox inbox;
  internal::DetectorInput detector_input;
  std::vector<teammate::ScanPoint> points;  // the detector's points of the scan
  internal::ScanReport report;              // the scan in flight
  double degenerate_average = 0.0;          // EMA of the own degeneracy flags
  Eigen::Vector3d last_gyro = Eigen::Vector3d::Zero();
  int64_t now_ns = std::numeric_limits<int64_t>::min();  // the newest sensor stamp
  lio::ScanContext scan;
  std::vector<DroneOutput> outputs;
};

std::string DroneEstimatorOptions::Validate() const {
  if (std::string e = odometry.Validate(); !e.empty()) return "odometry." + e;
  if (std::string e = teammate.Validate(); !e.empty()) return "teammate." + e;
  if (std::string e = swarm.Validate(); !e.empty()) return "swarm." + e;
  if (std::string e = airframe.Validate(); !e.empty()) return "airframe." + e;
  return "";
}

DroneEstimator::DroneEstimator(int self_id,
                               const DroneEstimatorOptions& options,
                               const LidarOptions& lidar)
    : self_id_(self_id), options_(options), lidar_(lidar) {}

DroneEstimator::~DroneEstimator() = default;

Status DroneEstimator::Create(int self_id,
                              const DroneEstimatorOptions& options,
                              const LidarOptions& lidar,
                              std::unique_ptr<DroneEstimator>* estimator) {
  if (self_id < 0) return Status::InvalidArgument("drone id must be >= 0");
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("drone estimator options: " + invalid);
  }
  std::unique_ptr<DroneEstimator> out(new DroneEstimator(self_id, options, lidar));
  SWARMLIO_RETURN_IF_ERROR(lio::Odometry::Create(options.odometry, lidar, &out->odometry_));
  out->detector_ = std::make_unique<teammate::TeammateDetector>(self_id, options.teammate);
  std::unique_ptr<net::ClockSync> clock_sync;
  if (options.swarm.synchronize_clocks) {
    SWARMLIO_RETURN_IF_ERROR(
        net::ClockSync::Create(self_id, options.swarm.clock_sync, &clock_sync));
  }
  out->parts_ = std::make_unique<Parts>(self_id, options, lidar, out->detector_.get(),
                                        std::move(clock_sync), &out->counters_);
  *estimator = std::move(out);
  return Status::Ok();
}

Status DroneEstimator::Add(const SensorRecord& record) {
  if (const auto* imu = std::get_if<ImuSample>(&record)) return AddImu(*imu);
  if (const auto* scan = std::get_if<LidarScan>(&record)) return AddScan(*scan);
  return AddMessage(std::get<net::ReceivedMessage>(record));
}

Status DroneEstimator::AddImu(const ImuSample& sample) {
  if (sample.angular_velocity_rad_s.allFinite()) parts_->last_gyro = sample.angular_velocity_rad_s;
  parts_->now_ns = std::max(parts_->now_ns, sample.stamp_ns);
  const Status status = odometry_->AddImu(sample);
  const Status processed = ProcessReadyScans(/*flush=*/false);
  return status.ok() ? processed : status;
}

Status DroneEstimator::AddScan(const LidarScan& scan) {
  parts_->now_ns = std::max(parts_->now_ns, scan.stamp_ns);
  const Status status = odometry_->AddScan(scan);
  const Status processed = ProcessReadyScans(/*flush=*/false);
  return status.ok() ? processed : status;
}

Status DroneEstimator::AddMessage(const net::ReceivedMessage& message) {
  internal::OwnSession own;
  own.started = odometry_->initialized();
  own.started_ns = odometry_->initialization().started_ns;
  parts_->inbox.Route(message, own);
  return Status::Ok();
}

Status DroneEstimator::Flush() {
  const Status status = ProcessReadyScans(/*flush=*/true);
  odometry_->FinishLog();
  return status;
}

void DroneEstimator::PopOutputs(std::vector<DroneOutput>* outputs) {
  for (DroneOutput& o : parts_->outputs) outputs->push_back(std::move(o));
  parts_->outputs.clear();
}

void DroneEstimator::PopMessages(std::vector<net::SwarmMessage>* messages) {
  parts_->broadcaster.TakeMessages(parts_->now_ns, messages);
}

const net::ClockSync* DroneEstimator::clock_sync() const { return parts_->clock_sync.get(); }

Status DroneEstimator::ProcessReadyScans(bool flush) {
  Status first_error;
  lio::ScanContext* scan = &parts_->scan;
  while (odometry_->NextScan(flush, scan)) {
    const Status status = scan->predicted ? ProcessScan(scan) : scan->status;
    if (!status.ok() && first_error.ok()) first_error = status;
  }
  return first_error;
}

Status DroneEstimator::ProcessScan(lio::ScanContext* scan) {
  const auto started = std::chrono::steady_clock::now();
  lio::UpdateRequest request;
  if (const Status status = FrontEnd(scan, &request); !status.ok()) {
    // The odometry still updates from the LiDAR; no teammate block moves.
    scan->out.front_end_error = status.message();
    request = lio::UpdateRequest();
    request.select_teammates = true;
  }
  scan->out.timings.front_end_s = SecondsSince(started);
  odometry_->Update(request, scan);
  lio::ScanOutput ego;
  const Status status = odometry_->Commit(scan, &ego);
  Finish(*scan, std::move(ego));
  return status;
}

Status DroneEstimator::FrontEnd(lio::ScanContext* scan, lio::UpdateRequest* request) {
  Parts& p = *parts_;
  p.report = internal::ScanReport();
  const int64_t t_k = scan->stamp_ns;
  const SwarmOptions& so = options_.swarm;
  SwarmState& x = scan->x;

  // Detection, tracking and identification at the predicted pose, on the
  // scan's reflective points at full resolution. The trackers read T_Gi_Gj
  // from the state (its one owner).
  SWARMLIO_RETURN_IF_ERROR(p.detector_input.Make(scan->raw, t_k, *scan->poses, x, p.detection,
                                                 p.last_detection_ns, detector_->min_reflectivity(),
                                                 &p.points));
  p.report.detector_points = static_cast<int>(p.points.size());
  for (int id : x.layout().teammate_ids()) {
    detector_->SetGlobalExtrinsic(id, x.teammate(id).T_Ga_Gb());
  }
  Eigen::Isometry3d T_Gi_bi = Eigen::Isometry3d::Identity();
  T_Gi_bi.linear() = x.ego.R_G_b();
  T_Gi_bi.translation() = x.ego.p_b_in_G;
  SWARMLIO_RETURN_IF_ERROR(detector_->ProcessScan(t_k, T_Gi_bi, p.points, &p.detection));
  p.last_detection_ns = t_k;

  // State blocks: new teammates in, lost or restarted ones out.
  p.registry.UpdateBlocks(t_k, p.detection, &x, &scan->P, &p.report, &counters_);

  // The updaters' terms. After a degenerate scan the observed extrinsics are
  // not corrected (degeneracy_policy): considered or held exact. A drone
  // relies on degenerate teammates only while it is degenerate most of the
  // time (an average of its flags over ~10 scans above one half).
  const bool degenerate = scan->previous_scan_degenerate;
  const bool frozen = so.degeneracy_policy != DegeneracyPolicy::kEstimateAll && degenerate;
  p.report.frozen = frozen && x.layout().NumTeammates() > 0;
  p.degenerate_average = 0.9 * p.degenerate_average + (degenerate ? 0.1 : 0.0);
  p.gate.Begin(&x, so.gate_sigma, frozen,
               so.degeneracy_policy == DegeneracyPolicy::kFreezeExtrinsics);
  internal::UpdaterScan u;
  u.t_k = t_k;
  u.x = &x;
  u.P = &scan->P;
  u.poses = scan->poses;
  u.fusion_enabled = fusion_enabled_;
  u.previous_scan_degenerate = degenerate;
  u.skip_degenerate = so.skip_degenerate_teammates && p.degenerate_average < 0.5;
  for (internal::MeasurementUpdater* updater : p.updaters) updater->AddTerms(u, &p.gate, &p.report);
  p.report.rejected += p.gate.rejected();
  counters_.observations_rejected += p.gate.rejected();
  p.gate.FillRequest(request);

  // Tracked objects stay out of the map.
  const Eigen::Isometry3d T_bi_Gi = T_Gi_bi.inverse();
  for (const teammate::TrackerState& s : p.detection.trackers) {
    scan->excluded.push_back({T_bi_Gi * s.p_in_Gi, so.map_exclusion_radius_m});
  }
  return Status::Ok();
}

void DroneEstimator::Finish(const lio::ScanContext& scan, lio::ScanOutput ego) {
  Parts& p = *parts_;
  if (!ego.front_end_error.empty()) ++counters_.front_end_errors;
  internal::ScanReport& r = p.report;
  DroneOutput d;
  d.teammates = p.registry.Estimates(ego.stamp_ns, scan.x, scan.P, r);
  d.identifications = std::move(r.identifications);
  d.removed_teammates = std::move(r.removed);
  d.active_observations = r.active;
  d.passive_observations = r.passive;
  d.gravity_alignments = r.gravity;
  d.rejected_observations = r.rejected;
  d.extrinsics_frozen = r.frozen;
  d.num_detector_points = r.detector_points;
  p.broadcaster.ForgetTeammates(d.removed_teammates);
  internal::BroadcastScan b;
  b.t_k = ego.stamp_ns;
  b.x = &scan.x;
  b.P = &scan.P;
  b.degenerate = ego.degenerate;
  b.session_start_ns = odometry_->initialization().stamp_ns;
  b.last_gyro = p.last_gyro;
  b.observations = &p.detection.observations;
  p.broadcaster.Broadcast(b);
  p.detection.observations.clear();
  p.report = internal::ScanReport();
  d.ego = std::move(ego);
  p.outputs.push_back(std::move(d));
}

}  // namespace swarmlio::swarm
