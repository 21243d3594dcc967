#include "swarmlio/sim/simulator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {
SensorCalibration TrueCalibration(const DroneConfig& drone) {
  SensorCalibration c;
  c.R_imu_lidar = drone.lidar.sensor.QuaternionImuLidar().toRotationMatrix();
  c.p_lidar_in_imu_m = drone.lidar.sensor.p_lidar_in_imu_m;
  c.imu_time_offset_s = drone.imu.time_offset_s;
  return c;
}

SensorCalibration GivenCalibration(const DroneConfig& drone) {
  SensorCalibration c = ApplyCalibrationError(TrueCalibration(drone), drone.calibration_error);
  if (drone.calibration_error.rotation_rad.isZero(0.0)) {
    c.R_imu_lidar = drone.lidar.sensor.R_imu_lidar;  // as configured, not re-projected
  }
  return c;
}

LidarOptions GivenLidarOptions(const DroneConfig& drone) {
  const SensorCalibration given = GivenCalibration(drone);
  LidarOptions lidar = drone.lidar.sensor;
  lidar.R_imu_lidar = given.R_imu_lidar;
  lidar.p_lidar_in_imu_m = given.p_lidar_in_imu_m;
  return lidar;
}

Simulator::Simulator(Scene scene, std::vector<DroneConfig> drones,
                     std::vector<MovingObjectConfig> objects, const SimulationConfig& config)
    : scene_(std::move(scene)),
      drones_(std::move(drones)),
      extra_objects_(std::move(objects)),
      config_(config) {
  if (!scene_.built()) scene_.Build();
  for (const DroneConfig& d : drones_) {
    MovingObject obj;
    obj.name = d.name;
    obj.trajectory = &d.trajectory;
    obj.parts_b = MakeDroneBody(d.body);
    obj.Finalize();
    objects_.push_back(std::move(obj));
  }
  for (const MovingObjectConfig& o : extra_objects_) {
    MovingObject obj;
    obj.name = o.name;
    obj.trajectory = &o.trajectory;
    obj.parts_b = o.parts_b;
    obj.Finalize();
    objects_.push_back(std::move(obj));
  }
}

Pose Simulator::T_W_G(int drone) const { return drones_.at(drone).trajectory.PoseAt(0.0); }

int64_t Simulator::StampNs(int drone, double t) const {
  const DroneConfig& d = drones_.at(drone);
  // Without drift this is exactly the drift-free expression (t * 1 == t).
  const double clock_t = t * (1.0 + d.clock_drift_ppm * 1e-6);
  return std::llround((config_.stamp_origin_s + clock_t + d.clock_offset_s) * 1e9);
}

ImuErrors Simulator::ImuErrorsOf(int drone) const {
  return ImuModel::DrawErrors(drones_.at(drone).imu,
                              DeriveSeed(config_.seed, drone, streams::kImu));
}

Status Simulator::Run(const std::vector<DroneSink*>& sinks, std::vector<DroneStats>* stats) const {
  if (sinks.size() != drones_.size()) {
    return Status::InvalidArgument("Simulator::Run: need one sink per drone");
  }
  const int n = static_cast<int>(drones_.size());
  std::vector<Status> results(n);
  std::vector<DroneStats> local_stats(n);
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) results[i] = RunDrone(i, sinks[i], &local_stats[i]);
  };
  const int num_threads = std::max(1, std::min(config_.num_threads, n));
  std::vector<std::thread> threads;
  for (int k = 1; k < num_threads; ++k) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  if (stats != nullptr) *stats = local_stats;
  for (int i = 0; i < n; ++i) {
    if (!results[i].ok()) return results[i].WithContext("drone " + drones_[i].name);
  }
  return Status::Ok();
}

Status Simulator::RunDrone(int drone, DroneSink* sink, DroneStats* stats) const {
  CHECK(sink != nullptr && stats != nullptr);
  *stats = DroneStats();
  const DroneConfig& d = drones_.at(drone);
  ImuModel imu(d.imu, &d.trajectory, 0.0, DeriveSeed(config_.seed, drone, streams::kImu));
  LidarModel lidar(d.lidar, &d.trajectory, &scene_, &objects_, drone,
                   DeriveSeed(config_.seed, drone, streams::kLidar));
  const Pose T_W_Gi = T_W_G(drone);
  const Eigen::Matrix3d R_G_W = T_W_Gi.R_W_b.transpose();
  const bool livox = d.lidar.sensor.message_format == LidarMessageFormat::kLivoxCustomMsg;
  const double gt_period = 1.0 / config_.ground_truth_rate_hz;
  int64_t gt_index = 0;
  SimulatedScan sim_scan;
  LidarScan scan;
  scan.frame_id = "livox_frame";
  for (int64_t frame = 0;; ++frame) {
    const double frame_end = lidar.FrameStart(frame) + lidar.period();
    if (frame_end > config_.duration_s + 1e-9) break;
    // IMU samples and ground truth up to the end of this frame, in time order.
    while (true) {
      const double t_imu = imu.next_time();
      const double t_gt = static_cast<double>(gt_index) * gt_period;
      if (t_imu >= frame_end && t_gt >= frame_end) break;
      if (t_imu <= t_gt) {
        const ImuMeasurement m = imu.Next();
        if (m.dropped) continue;  // lost on the way (imu.imperfections)
        ImuSample sample;
        sample.stamp_ns = StampNs(drone, m.t + d.imu.time_offset_s + m.stamp_jitter_s);
        sample.angular_velocity_rad_s = m.gyro;
        sample.linear_acceleration = m.accel;
        sample.frame_id = "livox_imu";
        SWARMLIO_RETURN_IF_ERROR(sink->OnImu(sample));
        ++stats->imu_samples;
      } else {
        const Pose T_W_b = d.trajectory.PoseAt(t_gt);
        PoseStamped pose;
        pose.stamp_ns = StampNs(drone, t_gt);
        pose.frame_id = "G_" + d.name;
        pose.q_G_b = Eigen::Quaterniond(R_G_W * T_W_b.R_W_b).normalized();
        pose.p_b_in_G = R_G_W * (T_W_b.p_b_in_W - T_W_Gi.p_b_in_W);
        SWARMLIO_RETURN_IF_ERROR(sink->OnGroundTruth(pose));
        ++gt_index;
      }
    }
    lidar.Scan(frame, &sim_scan);
    scan.stamp_ns = StampNs(drone, sim_scan.start_time_s);
    scan.livox_timebase_ns = livox ? static_cast<uint64_t>(scan.stamp_ns) : 0;
    scan.livox_lidar_id = 0;
    scan.points.resize(sim_scan.points.size());
    std::vector<int> returns_per_drone(drones_.size(), 0);
    bool sees_teammate = false;
    double last_point_t_s = sim_scan.start_time_s;
    for (size_t i = 0; i < sim_scan.points.size(); ++i) {
      const SimulatedPoint& p = sim_scan.points[i];
      last_point_t_s = std::max(last_point_t_s, p.t_s);
      LidarPoint& out = scan.points[i];
      out.x = static_cast<float>(p.p_in_lidar.x());
      out.y = static_cast<float>(p.p_in_lidar.y());
      out.z = static_cast<float>(p.p_in_lidar.z());
      out.reflectivity = static_cast<float>(p.reflectivity);
      // The sensor reports integer nanoseconds: quantise like the log will.
      out.offset_time_s = ToSeconds(StampNs(drone, p.t_s) - scan.stamp_ns);
      out.tag = p.tag;  // Livox: return number (0x10 first), normal point
      out.line = p.line;
      if (p.object >= 0 && p.object < static_cast<int>(drones_.size())) {
        ++stats->points_on_teammates;
        ++returns_per_drone[p.object];
        sees_teammate = true;
      }
      if (p.reflectivity > 150.0) ++stats->tape_points;
    }
    stats->points += static_cast<int64_t>(scan.points.size());
    stats->scans_seeing_teammates += sees_teammate;
    ++stats->scans;
    SWARMLIO_RETURN_IF_ERROR(sink->OnScan(scan, StampNs(drone, frame_end)));
    if (sees_teammate) {
      SWARMLIO_RETURN_IF_ERROR(sink->OnTeammateReturns(
          scan.stamp_ns, StampNs(drone, last_point_t_s), returns_per_drone));
    }
  }
  return Status::Ok();
}

}  // namespace swarmlio::sim
