#include "sim_harness.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>

#include "swarmlio/lio/odometry.h"
#include "swarmlio/driver/manifest.h"

namespace swarmlio::teammate::harness {
namespace {

double TrueTime(const sim::Simulator& sim, int drone, int64_t stamp_ns) {
  return static_cast<double>(stamp_ns - sim.StampNs(drone, 0.0)) * 1e-9;
}

Eigen::Isometry3d ToIsometry(const sim::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = pose.R_W_b;
  T.translation() = pose.p_b_in_W;
  return T;
}

struct Delivery {
  double arrival_true_s = 0.0;
  TeammateOdometry odometry;
};

// Every teammate's broadcasts, as the observer receives them, by arrival time.
std::vector<Delivery> MakeBroadcasts(const sim::Simulator& sim, int observer,
                                     const HarnessOptions& options) {
  std::vector<Delivery> out;
  const int n = static_cast<int>(sim.drones().size());
  for (int j = 0; j < n; ++j) {
    if (j == observer) continue;
    const sim::DroneConfig& d = sim.drones()[static_cast<size_t>(j)];
    std::mt19937_64 rng(sim::DeriveSeed(options.seed, static_cast<uint64_t>(observer),
                                        static_cast<uint64_t>(j)));
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const Eigen::Isometry3d T_Gj_W = ToIsometry(sim.T_W_G(j)).inverse();
    const double period = 1.0 / d.lidar.sensor.scan_rate_hz;
    for (int k = 1;; ++k) {
      const double t = d.lidar.start_time_s + k * period;
      if (t > sim.config().duration_s + 1e-9) break;
      if (uniform(rng) < options.drop_probability) continue;
      Delivery delivery;
      delivery.arrival_true_s = t + options.latency_s;
      TeammateOdometry& m = delivery.odometry;
      m.drone_id = j;
      m.stamp_ns = sim.StampNs(observer, t);
      if (options.ego_estimates != nullptr) {
        EgoEstimate s;
        if (!(*options.ego_estimates)[static_cast<size_t>(j)].StateAt(sim.StampNs(j, t), &s)) {
          continue;  // no estimate yet: nothing to broadcast
        }
        m.p_bj_in_Gj = s.p_b_in_G;
        m.q_Gj_bj = s.q_G_b;
        m.v_bj_in_Gj = s.v_b_in_G;
      } else {
        const sim::KinematicState s = d.trajectory.StateAt(t);
        m.p_bj_in_Gj = T_Gj_W * s.p_b_in_W;
        m.q_Gj_bj = Eigen::Quaterniond(T_Gj_W.linear() * s.R_W_b).normalized();
        m.v_bj_in_Gj = T_Gj_W.linear() * s.v_b_in_W;
      }
      out.push_back(delivery);
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Delivery& a, const Delivery& b) {
    return a.arrival_true_s < b.arrival_true_s;
  });
  return out;
}

// The observer's scans as detector inputs. Ego poses are taken in a frame F:
// W for the true trajectory (T_Gi_F_ = T_Gi_W), G_i itself for the estimate
// (T_Gi_F_ = identity), so the true-pose arithmetic is the original one.
class HarnessSink : public sim::DroneSink {
 public:
  HarnessSink(const sim::Simulator& sim, int observer, const HarnessOptions& options,
              const ScanCallback& callback)
      : sim_(sim),
        observer_(observer),
        options_(options),
        callback_(callback),
        deliveries_(MakeBroadcasts(sim, observer, options)) {
    const sim::DroneConfig& d = sim.drones()[static_cast<size_t>(observer)];
    if (options.ego_estimates != nullptr) {
      estimate_ = &(*options.ego_estimates)[static_cast<size_t>(observer)];
      // The extrinsic the odometry was given, as the estimated poses are its.
      R_imu_lidar_ = estimate_->calibration.R_imu_lidar;
      p_lidar_in_imu_ = estimate_->calibration.p_lidar_in_imu_m;
      T_Gi_F_ = Eigen::Isometry3d::Identity();
    } else {
      // The true extrinsic (the sensor as simulated), with the true poses.
      R_imu_lidar_ = d.lidar.sensor.QuaternionImuLidar().toRotationMatrix();
      p_lidar_in_imu_ = d.lidar.sensor.p_lidar_in_imu_m;
      T_Gi_F_ = ToIsometry(sim.T_W_G(observer)).inverse();
    }
  }

  Status OnImu(const ImuSample&) override { return Status::Ok(); }
  Status OnGroundTruth(const PoseStamped&) override { return Status::Ok(); }

  Status OnScan(const LidarScan& scan, int64_t record_time_ns) override {
    const double t_start = TrueTime(sim_, observer_, scan.stamp_ns);
    const double t_end = TrueTime(sim_, observer_, record_time_ns);
    Eigen::Isometry3d T_F_bend;
    if (!PoseAt(t_end, record_time_ns, &T_F_bend)) {
      ++scans_without_pose_;
      return Status::Ok();
    }
    const Eigen::Isometry3d T_bend_F = T_F_bend.inverse();
    // Body pose at 1 ms steps over the frame, relative to the body at its end.
    const double dt = options_.pose_sample_dt_s;
    const int num_samples = static_cast<int>(std::ceil((t_end - t_start) / dt)) + 1;
    T_bend_bk_.resize(static_cast<size_t>(num_samples));
    for (int k = 0; k < num_samples; ++k) {
      const int64_t stamp_ns =
          std::min<int64_t>(scan.stamp_ns + ToNanoseconds(k * dt), record_time_ns);
      Eigen::Isometry3d T_F_bk;
      if (!PoseAt(t_start + k * dt, stamp_ns, &T_F_bk)) {
        ++scans_without_pose_;  // the frame began before the first estimate
        return Status::Ok();
      }
      T_bend_bk_[static_cast<size_t>(k)] = T_bend_F * T_F_bk;
    }
    PreparedScan& out = prepared_;
    out.observer = observer_;
    out.stamp_ns = record_time_ns;
    out.t_true_s = t_end;
    out.T_Gi_bi = T_Gi_F_ * T_F_bend;
    out.points.resize(scan.points.size());
    for (size_t i = 0; i < scan.points.size(); ++i) {
      const LidarPoint& p = scan.points[i];
      const double t_point = t_start + p.offset_time_s;
      const int k = std::clamp(static_cast<int>(std::lround(p.offset_time_s / dt)), 0, num_samples - 1);
      const Eigen::Vector3d p_in_b =
          R_imu_lidar_ * Eigen::Vector3d(p.x, p.y, p.z) + p_lidar_in_imu_;
      ScanPoint& q = out.points[i];
      q.p_in_b = (T_bend_bk_[static_cast<size_t>(k)] * p_in_b).cast<float>();
      q.reflectivity = p.reflectivity;
      q.time_offset_s = static_cast<float>(t_point - t_end);
    }
    out.odometry.clear();
    while (next_delivery_ < deliveries_.size() &&
           deliveries_[next_delivery_].arrival_true_s <= t_end) {
      out.odometry.push_back(deliveries_[next_delivery_++].odometry);
    }
    return callback_(out);
  }

  int scans_without_pose() const { return scans_without_pose_; }

 private:
  // The observer's body pose in F at true time t (its clock: stamp_ns).
  bool PoseAt(double t, int64_t stamp_ns, Eigen::Isometry3d* T_F_b) const {
    if (estimate_ == nullptr) {
      *T_F_b = ToIsometry(sim_.drones()[static_cast<size_t>(observer_)].trajectory.PoseAt(t));
      return true;
    }
    EgoEstimate s;
    if (!estimate_->StateAt(stamp_ns, &s)) return false;
    *T_F_b = Eigen::Isometry3d::Identity();
    T_F_b->linear() = s.q_G_b.toRotationMatrix();
    T_F_b->translation() = s.p_b_in_G;
    return true;
  }

  const sim::Simulator& sim_;
  int observer_;
  HarnessOptions options_;
  const ScanCallback& callback_;
  std::vector<Delivery> deliveries_;
  size_t next_delivery_ = 0;
  const EstimatedTrajectory* estimate_ = nullptr;  // nullptr: true poses
  Eigen::Matrix3d R_imu_lidar_;
  Eigen::Vector3d p_lidar_in_imu_;
  Eigen::Isometry3d T_Gi_F_;
  std::vector<Eigen::Isometry3d> T_bend_bk_;
  PreparedScan prepared_;
  int scans_without_pose_ = 0;
};

// Feeds one drone's simulated IMU and scans to its odometry and keeps the
// output state of every scan.
class OdometrySink : public sim::DroneSink {
 public:
  OdometrySink(lio::Odometry* odometry, std::vector<EgoEstimate>* states)
      : odometry_(odometry), states_(states) {}

  Status OnImu(const ImuSample& imu) override {
    // Data problems are counted by the odometry; only real errors fail the run.
    Status status = odometry_->AddImu(imu);
    if (status.ok()) status = Collect(/*flush=*/false);
    return status.code() == Status::Code::kInvalidArgument ? Status::Ok() : status;
  }
  Status OnScan(const LidarScan& scan, int64_t) override {
    Status status = odometry_->AddScan(scan);
    const Status processed = Collect(/*flush=*/false);
    if (status.ok()) status = processed;
    return status.code() == Status::Code::kInvalidArgument ? Status::Ok() : status;
  }
  Status OnGroundTruth(const PoseStamped&) override { return Status::Ok(); }

  // The scans ready (every queued one with `flush`, at the end of the run).
  Status Collect(bool flush) {
    outputs_.clear();
    const Status status = odometry_->ProcessReadyScans(flush, &outputs_);
    for (const lio::ScanOutput& o : outputs_) {
      if (!states_->empty() && o.stamp_ns <= states_->back().stamp_ns) continue;
      EgoEstimate s;
      s.stamp_ns = o.stamp_ns;
      s.q_G_b = o.state.q_G_b.normalized();
      s.p_b_in_G = o.state.p_b_in_G;
      s.v_b_in_G = o.state.v_b_in_G;
      states_->push_back(s);
    }
    return status;
  }

 private:
  lio::Odometry* odometry_;
  std::vector<EgoEstimate>* states_;
  std::vector<lio::ScanOutput> outputs_;
};

double RotationAngleDeg(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI;
}

}  // namespace

bool EstimatedTrajectory::StateAt(int64_t stamp_ns, EgoEstimate* state) const {
  if (states.empty() || stamp_ns < states.front().stamp_ns ||
      stamp_ns > states.back().stamp_ns + kMaxExtrapolationNs) {
    return false;
  }
  const auto after = std::lower_bound(
      states.begin(), states.end(), stamp_ns,
      [](const EgoEstimate& s, int64_t stamp) { return s.stamp_ns < stamp; });
  if (after == states.end()) {
    *state = states.back();
    state->p_b_in_G += SecondsBetween(state->stamp_ns, stamp_ns) * state->v_b_in_G;
  } else if (after->stamp_ns == stamp_ns) {
    *state = *after;
  } else {
    const EgoEstimate& a = *(after - 1);
    const EgoEstimate& b = *after;
    const double w = static_cast<double>(stamp_ns - a.stamp_ns) /
                     static_cast<double>(b.stamp_ns - a.stamp_ns);
    state->p_b_in_G = (1.0 - w) * a.p_b_in_G + w * b.p_b_in_G;
    state->v_b_in_G = (1.0 - w) * a.v_b_in_G + w * b.v_b_in_G;
    state->q_G_b = a.q_G_b.slerp(w, b.q_G_b);
  }
  state->stamp_ns = stamp_ns;
  return true;
}

Status EstimateEgoTrajectories(const sim::Simulator& sim,
                               std::vector<EstimatedTrajectory>* trajectories) {
  const size_t n = sim.drones().size();
  trajectories->assign(n, EstimatedTrajectory());
  std::vector<std::unique_ptr<lio::Odometry>> odometries(n);
  std::vector<std::unique_ptr<OdometrySink>> sinks(n);
  std::vector<sim::DroneSink*> sink_pointers(n);
  for (size_t j = 0; j < n; ++j) {
    const sim::DroneConfig& d = sim.drones()[j];
    EstimatedTrajectory& out = (*trajectories)[j];
    // The calibration handed to the estimator (with the scenario's error), as
    // a real drone's swarm.yaml would be: not the truth the simulator uses.
    out.calibration = sim::GivenCalibration(d);
    const LidarOptions lidar = sim::GivenLidarOptions(d);
    lio::OdometryOptions options = driver::DefaultOdometryOptions(lidar, d.imu.sensor);
    options.imu_time_offset_s = out.calibration.imu_time_offset_s;
    SWARMLIO_RETURN_IF_ERROR(lio::Odometry::Create(options, lidar, &odometries[j]));
    sinks[j] = std::make_unique<OdometrySink>(odometries[j].get(), &out.states);
    sink_pointers[j] = sinks[j].get();
  }
  // The drones in parallel (SimulationConfig::num_threads), each with its
  // own odometry: the result does not depend on the scheduling.
  SWARMLIO_RETURN_IF_ERROR(sim.Run(sink_pointers, nullptr));
  for (size_t j = 0; j < n; ++j) {
    const Status flushed = sinks[j]->Collect(/*flush=*/true);
    if (!flushed.ok() && flushed.code() != Status::Code::kInvalidArgument) {
      return flushed.WithContext("drone " + sim.drones()[j].name);
    }
  }
  return Status::Ok();
}

void EstimateErrors(const sim::Simulator& sim, int drone, const EstimatedTrajectory& estimate,
                    double* max_position_error_m, double* max_rotation_error_deg) {
  const Eigen::Isometry3d T_G_W = ToIsometry(sim.T_W_G(drone)).inverse();
  *max_position_error_m = 0.0;
  *max_rotation_error_deg = 0.0;
  for (const EgoEstimate& s : estimate.states) {
    const double t = TrueTime(sim, drone, s.stamp_ns);
    const Eigen::Isometry3d T_G_b =
        T_G_W * ToIsometry(sim.drones()[static_cast<size_t>(drone)].trajectory.PoseAt(t));
    *max_position_error_m =
        std::max(*max_position_error_m, (s.p_b_in_G - T_G_b.translation()).norm());
    *max_rotation_error_deg =
        std::max(*max_rotation_error_deg,
                 RotationAngleDeg(T_G_b.linear().transpose() * s.q_G_b.toRotationMatrix()));
  }
}

Status SimulateObserver(const sim::Simulator& sim, int observer, const HarnessOptions& options,
                        const ScanCallback& callback, int* scans_without_pose) {
  if (options.ego_estimates != nullptr && options.ego_estimates->size() != sim.drones().size()) {
    return Status::InvalidArgument("SimulateObserver: need one ego estimate per drone");
  }
  HarnessSink sink(sim, observer, options, callback);
  sim::DroneStats stats;
  const Status status = sim.RunDrone(observer, &sink, &stats);
  if (scans_without_pose != nullptr) *scans_without_pose = sink.scans_without_pose();
  return status;
}

Eigen::Isometry3d TrueGlobalExtrinsic(const sim::Simulator& sim, int i, int j) {
  return ToIsometry(sim.T_W_G(i)).inverse() * ToIsometry(sim.T_W_G(j));
}

Eigen::Vector3d TruePositionInBody(const sim::Simulator& sim, int i, int j, double t) {
  const sim::Pose bi = sim.drones()[static_cast<size_t>(i)].trajectory.PoseAt(t);
  const Eigen::Vector3d p_bj_in_W = sim.drones()[static_cast<size_t>(j)].trajectory.PositionAt(t);
  return bi.R_W_b.transpose() * (p_bj_in_W - bi.p_b_in_W);
}

double ExcitationStartTime(const sim::Simulator& sim, int j) {
  const sim::Trajectory& trajectory = sim.drones()[static_cast<size_t>(j)].trajectory;
  for (double t = 0.0; t <= sim.config().duration_s; t += 0.01) {
    if (trajectory.StateAt(t).v_b_in_W.head<2>().norm() > 0.05) return t;
  }
  return std::numeric_limits<double>::infinity();
}

Status EvaluateObserver(const sim::Simulator& sim, int observer,
                        const TeammateDetectorOptions& detector_options,
                        const HarnessOptions& options, ObserverReport* report,
                        const ResultCallback& on_result) {
  *report = ObserverReport();
  report->observer = observer;
  const int n = static_cast<int>(sim.drones().size());
  std::vector<double> excitation_start(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) excitation_start[static_cast<size_t>(j)] = ExcitationStartTime(sim, j);
  const Eigen::Isometry3d T_W_Gi = ToIsometry(sim.T_W_G(observer));
  TeammateDetector detector(observer, detector_options);
  ScanResult result;
  report->visibility.assign(static_cast<size_t>(n), VisibilityRecord());
  const float min_reflectivity = static_cast<float>(detector_options.clustering.min_reflectivity);

  // The drone nearest to p_W at time t (other than the observer) and its distance.
  auto nearest_drone = [&](const Eigen::Vector3d& p_W, double t, double* distance) {
    int best = -1;
    *distance = std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j) {
      if (j == observer) continue;
      const double d = (sim.drones()[static_cast<size_t>(j)].trajectory.PositionAt(t) - p_W).norm();
      if (d < *distance) {
        *distance = d;
        best = j;
      }
    }
    return best;
  };

  const ScanCallback callback = [&](const PreparedScan& scan) -> Status {
    for (const TeammateOdometry& m : scan.odometry) detector.AddTeammateOdometry(m);
    const auto start = std::chrono::steady_clock::now();
    SWARMLIO_RETURN_IF_ERROR(detector.ProcessScan(scan.stamp_ns, scan.T_Gi_bi, scan.points, &result));
    report->process_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    report->scan_sizes.push_back(static_cast<int>(scan.points.size()));
    ++report->scans;
    report->points += static_cast<int64_t>(scan.points.size());
    const double t = scan.t_true_s;
    for (int j = 0; j < n; ++j) {
      if (j == observer) continue;
      const Eigen::Vector3f truth = TruePositionInBody(sim, observer, j, t).cast<float>();
      int on = 0, tape = 0;
      for (const ScanPoint& p : scan.points) {
        if ((p.p_in_b - truth).squaredNorm() > 0.09f) continue;
        ++on;
        tape += p.reflectivity >= min_reflectivity;
      }
      VisibilityRecord& v = report->visibility[static_cast<size_t>(j)];
      v.scans_with_points += on >= 3;
      v.scans_with_tape += tape >= 3;
      if (tape >= 3 && v.first_tape_s < 0.0 &&
          t >= std::max(excitation_start[static_cast<size_t>(observer)],
                        excitation_start[static_cast<size_t>(j)])) {
        v.first_tape_s = t;
      }
    }

    for (const TeammateIdentification& id : result.identifications) {
      IdentificationRecord r;
      r.observer = observer;
      r.teammate = id.drone_id;
      r.t_true_s = t;
      r.since_excitation_s = t - std::max(excitation_start[static_cast<size_t>(observer)],
                                          excitation_start[static_cast<size_t>(id.drone_id)]);
      const double first_tape = report->visibility[static_cast<size_t>(id.drone_id)].first_tape_s;
      r.since_visible_s = t - std::max(t - r.since_excitation_s, first_tape);
      const Eigen::Isometry3d T_true = TrueGlobalExtrinsic(sim, observer, id.drone_id);
      r.translation_error_m = (id.p_Gj_in_Gi - T_true.translation()).norm();
      r.rotation_error_deg = RotationAngleDeg(T_true.linear().transpose() * id.R_Gi_Gj);
      const Eigen::AngleAxisd error(id.R_Gi_Gj * T_true.linear().transpose());
      r.yaw_error_deg = error.angle() * error.axis().z() * 180.0 / M_PI;
      r.mean_residual_m = id.mean_residual_m;
      r.second_best_residual_m = id.second_best_residual_m;
      r.num_pairs = id.num_pairs;
      for (const TrackerState& s : result.trackers) {
        if (s.tracker_id != id.tracker_id) continue;
        double distance = 0.0;
        const int j = nearest_drone(T_W_Gi * s.p_in_Gi, t, &distance);
        r.correct = (j == id.drone_id && distance < 0.3);
      }
      report->identifications.push_back(r);
    }
    for (const TeammateObservation& o : result.observations) {
      ObservationRecord r;
      r.observer = observer;
      r.teammate = o.drone_id;
      r.t_true_s = t;
      const Eigen::Vector3d truth = TruePositionInBody(sim, observer, o.drone_id, t);
      r.range_m = truth.norm();
      r.error_m = (o.p_bj_in_bi - truth).norm();
      r.along_error_m = (o.p_bj_in_bi - truth).dot(truth.normalized());
      r.vertical_error_m = o.p_bj_in_bi.z() - truth.z();
      if (r.error_m > 0.3) ++report->wrong_observations;
      report->observations.push_back(r);
    }
    for (const TrackerState& s : result.trackers) {
      if (!s.created || s.drone_id >= 0) continue;
      double distance = 0.0;
      nearest_drone(T_W_Gi * s.p_in_Gi, t, &distance);
      if (distance < 0.5) {
        ++report->temporary_on_teammates;
      } else {
        ++report->temporary_elsewhere;
      }
    }
    if (on_result) on_result(scan, result);
    return Status::Ok();
  };
  return SimulateObserver(sim, observer, options, callback, &report->scans_without_pose);
}

}  // namespace swarmlio::teammate::harness
