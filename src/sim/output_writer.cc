#include "swarmlio/sim/output_writer.h"

#include <cinttypes>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "swarmlio/common/check.h"
#include "swarmlio/config/dump_options.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/sim/airframe_description.h"

namespace swarmlio::sim {
namespace {

std::string Vec(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << std::setprecision(17) << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

// Row-major, as the YAML of Eigen::Matrix3d options.
std::string Mat(const Eigen::Matrix3d& m) {
  std::ostringstream os;
  os << std::setprecision(17) << "[";
  for (int i = 0; i < 9; ++i) os << (i ? ", " : "") << m(i / 3, i % 3);
  os << "]";
  return os.str();
}

std::string Quat(const Eigen::Quaterniond& q) {
  std::ostringstream os;
  os << std::setprecision(17) << "[" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w()
     << "]";
  return os.str();
}

std::string Indented(const std::string& block, const std::string& indent) {
  std::ostringstream os;
  std::istringstream lines(block);
  for (std::string line; std::getline(lines, line);) os << indent << line << "\n";
  return os.str();
}

}  // namespace

std::string ResolvedScenarioYaml(const Scenario& s, const Simulator& sim) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "# Resolved scenario '" << s.options.name << "' (written by swarmlio_sim)\n";
  os << config::DumpOptions(s.options, "scenario");
  os << "imperfections: " << config::EnumToString(s.imperfections) << "\n";
  os << "num_static_primitives: " << sim.scene().primitives().size() << "\n";
  os << "drones:\n";
  for (size_t i = 0; i < sim.drones().size(); ++i) {
    const DroneConfig& d = sim.drones()[i];
    const Pose T = sim.T_W_G(static_cast<int>(i));
    os << "  - name: " << d.name << "\n";
    os << "    # Global frame G_i = IMU frame at t = 0, in the simulation world W\n";
    os << "    p_Gi_in_W_m: " << Vec(T.p_b_in_W) << "\n";
    os << "    q_W_Gi_xyzw: " << Quat(Eigen::Quaterniond(T.R_W_b)) << "\n";
    os << "    q_imu_lidar_xyzw: " << Quat(d.lidar.sensor.QuaternionImuLidar()) << "\n";
    os << "    clock_offset_s: " << d.clock_offset_s << "\n";
    os << "    clock_drift_ppm: " << d.clock_drift_ppm << "\n";
    const std::string block = config::DumpOptions(d.lidar, "lidar") +
                              config::DumpOptions(d.imu, "imu") +
                              config::DumpOptions(d.body, "body");
    os << Indented(block, "    ");
    os << "    # centroid of the airframe's reflective parts in the body (IMU) frame b\n";
    os << "    p_reflective_centroid_in_b_m: "
       << Vec(ReflectiveCentroidInBody(MakeDroneBody(d.body))) << "\n";
    const SensorCalibration truth = TrueCalibration(d);
    const SensorCalibration given = GivenCalibration(d);
    const ImuErrors imu = sim.ImuErrorsOf(static_cast<int>(i));
    os << "    # The truth of this drone's sensors and clock (for evaluation): the\n"
          "    # simulation used these; swarm.yaml hands the estimator `given_calibration`.\n";
    os << "    truth:\n";
    os << "      R_imu_lidar: " << Mat(truth.R_imu_lidar) << "\n";
    os << "      p_lidar_in_imu_m: " << Vec(truth.p_lidar_in_imu_m) << "\n";
    os << "      imu_time_offset_s: " << truth.imu_time_offset_s << "\n";
    os << "      # drone clock = stamp_origin_s + t * (1 + clock_drift_ppm * 1e-6) + "
          "clock_offset_s\n";
    os << "      clock_offset_s: " << d.clock_offset_s << "\n";
    os << "      clock_drift_ppm: " << d.clock_drift_ppm << "\n";
    os << "      # gyro = M_g (w + vibration) + ..., accel = M_a (f + vibration) + ...\n";
    os << "      imu_gyro_matrix: " << Mat(imu.gyro_matrix) << "\n";
    os << "      imu_accel_matrix: " << Mat(imu.accel_matrix) << "\n";
    os << "      imu_gyro_vibration_phase_rad: " << Vec(imu.gyro_phase_rad) << "\n";
    os << "      imu_gyro_vibration_harmonic_phase_rad: " << Vec(imu.gyro_harmonic_phase_rad)
       << "\n";
    os << "      imu_accel_vibration_phase_rad: " << Vec(imu.accel_phase_rad) << "\n";
    os << "      imu_accel_vibration_harmonic_phase_rad: " << Vec(imu.accel_harmonic_phase_rad)
       << "\n";
    os << "    given_calibration:\n";
    os << "      R_imu_lidar: " << Mat(given.R_imu_lidar) << "\n";
    os << "      p_lidar_in_imu_m: " << Vec(given.p_lidar_in_imu_m) << "\n";
    os << "      imu_time_offset_s: " << given.imu_time_offset_s << "\n";
    os << "      # given = truth (+) error: R_given = R_true Exp(rotation_error_rad)\n";
    os << "      rotation_error_rad: " << Vec(d.calibration_error.rotation_rad) << "\n";
    os << "      rotation_error_deg: " << d.calibration_error.rotation_rad.norm() * 180.0 / M_PI
       << "\n";
    os << "      translation_error_m: " << Vec(d.calibration_error.translation_m) << "\n";
    os << "      imu_time_offset_error_s: " << d.calibration_error.imu_time_offset_s << "\n";
  }
  return os.str();
}

std::string ReplayManifestYaml(const Scenario& s, const Simulator& sim) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "# Replay manifest of the simulated run (written by swarmlio_sim).\n";
  os << "# swarmlio_replay --manifest=<this file> --output_dir=...\n";
  os << "# The extrinsic (lidar.R_imu_lidar, lidar.p_lidar_in_imu_m) and\n";
  os << "# odometry.imu_time_offset_s are the calibration handed to the estimator\n";
  os << "# (imperfections: " << config::EnumToString(s.imperfections)
     << "); the truth is in resolved_scenario.yaml (drones[i].truth).\n";
  os << "name: " << s.options.name << "\n";
  os << "drones:\n";
  for (size_t i = 0; i < sim.drones().size(); ++i) {
    const DroneConfig& d = sim.drones()[i];
    const Pose T = sim.T_W_G(static_cast<int>(i));
    const LidarOptions lidar = GivenLidarOptions(d);
    os << "  - name: " << d.name << "\n";
    os << "    bag: " << BagFileName(d.name, s.bag) << "\n";
    os << "    # G_i in the simulation world W (for plots)\n";
    os << "    p_G_in_W_m: " << Vec(T.p_b_in_W) << "\n";
    os << "    q_W_G_xyzw: " << Quat(Eigen::Quaterniond(T.R_W_b)) << "\n";
    os << "    ground_truth: " << d.name << "_gt_tum.txt\n";
    os << "    # returns of each scan on each teammate's body (truth, for evaluation)\n";
    os << "    teammate_returns: " << d.name << "_teammate_returns.csv\n";
    os << "    # the drone's clock (truth, for packet delivery in the replay only)\n";
    os << "    true_clock: {offset_s: " << d.clock_offset_s << ", drift_ppm: " << d.clock_drift_ppm
       << ", origin_s: " << sim.config().stamp_origin_s << "}\n";
    os << "    # the airframe as its owner describes it (announced to the teammates)\n";
    os << Indented(config::DumpOptions(DescribeAirframe(d.body), "airframe"), "    ");
    os << Indented(config::DumpOptions(lidar, "lidar"), "    ");
    os << Indented(config::DumpOptions(d.imu.sensor, "imu"), "    ");
    os << "    odometry:\n";
    os << "      # IMU stamps later than the LiDAR's (as calibrated)\n";
    os << "      imu_time_offset_s: " << GivenCalibration(d).imu_time_offset_s << "\n";
  }
  return os.str();
}

io::BagWriterOptions BagOptionsFor(const io::BagWriterOptions& base, const LidarOptions& lidar) {
  io::BagWriterOptions options = base;
  options.lidar_format = lidar.message_format;
  options.point_time_unit = lidar.timestamp_unit;
  return options;
}

std::string BagFileName(const std::string& name, const io::BagWriterOptions& options) {
  switch (options.format) {
    case io::BagFormat::kMcap:
      return name + ".mcap";
    case io::BagFormat::kDb3:
      return name + ".db3";
    default:
      return name + ".bag";
  }
}

Status DroneOutputWriter::Open(const std::string& bag_path, const std::string& tum_path,
                               const io::BagWriterOptions& options,
                               std::unique_ptr<DroneOutputWriter>* writer) {
  std::unique_ptr<DroneOutputWriter> w(new DroneOutputWriter());
  SWARMLIO_RETURN_IF_ERROR(io::BagWriter::Open(bag_path, options, &w->bag_));
  w->tum_path_ = tum_path;
  w->tum_.open(tum_path, std::ios::out | std::ios::trunc);
  if (!w->tum_) return Status::IoError(tum_path + ": cannot open for writing");
  *writer = std::move(w);
  return Status::Ok();
}

Status DroneOutputWriter::OnImu(const ImuSample& imu) { return bag_->WriteImu(imu); }

Status DroneOutputWriter::OnScan(const LidarScan& scan, int64_t record_time_ns) {
  return bag_->WriteScan(scan, record_time_ns);
}

Status DroneOutputWriter::OnGroundTruth(const PoseStamped& pose) {
  SWARMLIO_RETURN_IF_ERROR(bag_->WriteGroundTruth(pose));
  char line[256];
  const Eigen::Quaterniond& q = pose.q_G_b;
  std::snprintf(line, sizeof(line), "%" PRId64 ".%09" PRId64 " %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n",
                pose.stamp_ns / 1000000000, pose.stamp_ns % 1000000000, pose.p_b_in_G.x(),
                pose.p_b_in_G.y(), pose.p_b_in_G.z(), q.x(), q.y(), q.z(), q.w());
  tum_ << line;
  if (!tum_) return Status::IoError(tum_path_ + ": write failed");
  return Status::Ok();
}

Status DroneOutputWriter::WriteTeammateReturnsTo(const std::string& csv_path,
                                                 std::vector<std::string> drone_names) {
  returns_path_ = csv_path;
  drone_names_ = std::move(drone_names);
  returns_.open(csv_path, std::ios::out | std::ios::trunc);
  if (!returns_) return Status::IoError(csv_path + ": cannot open for writing");
  returns_ << "scan_stamp_s,scan_end_s,teammate,returns\n";
  return Status::Ok();
}

Status DroneOutputWriter::OnTeammateReturns(int64_t scan_stamp_ns, int64_t scan_end_ns,
                                            const std::vector<int>& returns_per_drone) {
  if (!returns_.is_open()) return Status::Ok();
  for (size_t k = 0; k < returns_per_drone.size() && k < drone_names_.size(); ++k) {
    if (returns_per_drone[k] <= 0) continue;
    char line[160];
    std::snprintf(line, sizeof(line), "%" PRId64 ".%09" PRId64 ",%" PRId64 ".%09" PRId64 ",",
                  scan_stamp_ns / 1000000000, scan_stamp_ns % 1000000000,
                  scan_end_ns / 1000000000, scan_end_ns % 1000000000);
    returns_ << line << drone_names_[k] << "," << returns_per_drone[k] << "\n";
  }
  if (!returns_) return Status::IoError(returns_path_ + ": write failed");
  return Status::Ok();
}

Status DroneOutputWriter::Close() {
  tum_.close();
  if (tum_.fail()) return Status::IoError(tum_path_ + ": close failed");
  if (returns_.is_open()) {
    returns_.close();
    if (returns_.fail()) return Status::IoError(returns_path_ + ": close failed");
  }
  return bag_->Close();
}

}  // namespace swarmlio::sim
