// swarmlio_sim: runs a scenario and writes, per drone, a ROS1 bag
// (<name>.bag: /livox/lidar, /livox/imu, /ground_truth/pose), a TUM ground
// truth file in the drone's global frame (<name>_gt_tum.txt), and the resolved
// scenario (resolved_scenario.yaml: T_W_Gi, extrinsics, noise settings) and
// the replay manifest (swarm.yaml) for swarmlio_replay.
//
//   swarmlio_sim --scenario=configs/scenarios/indoor_3uav.yaml --output_dir=out
#include <gflags/gflags.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

#include "swarmlio/config/dump_options.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"

DEFINE_string(scenario, "", "scenario YAML file (configs/scenarios/*.yaml)");
DEFINE_string(output_dir, "", "output folder (created)");
DEFINE_double(duration_s, 0.0, "override the scenario duration when > 0");
DEFINE_int64(seed, -1, "override the scenario seed when >= 0");
DEFINE_int32(threads, 0, "override the number of worker threads when > 0");

namespace swarmlio::sim {
namespace {

std::string Vec(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << std::setprecision(17) << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

std::string Indented(const std::string& block, const std::string& indent) {
  std::ostringstream os;
  std::istringstream lines(block);
  for (std::string line; std::getline(lines, line);) os << indent << line << "\n";
  return os.str();
}

std::string Resolved(const Scenario& s, const Simulator& sim) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "# Resolved scenario '" << s.options.name << "' (written by swarmlio_sim)\n";
  os << config::DumpOptions(s.options, "scenario");
  os << "num_static_primitives: " << sim.scene().primitives().size() << "\n";
  os << "drones:\n";
  for (size_t i = 0; i < s.drones.size(); ++i) {
    const DroneConfig& d = s.drones[i];
    const Pose T = sim.T_W_G(static_cast<int>(i));
    const Eigen::Quaterniond q(T.R_W_b);
    const Eigen::Quaterniond q_il = d.lidar.sensor.QuaternionImuLidar();
    os << "  - name: " << d.name << "\n";
    os << "    # Global frame G_i = IMU frame at t = 0, in the simulation world W\n";
    os << "    p_Gi_in_W_m: " << Vec(T.p_b_in_W) << "\n";
    os << "    q_W_Gi_xyzw: [" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w()
       << "]\n";
    os << "    q_imu_lidar_xyzw: [" << q_il.x() << ", " << q_il.y() << ", " << q_il.z() << ", "
       << q_il.w() << "]\n";
    os << "    clock_offset_s: " << d.clock_offset_s << "\n";
    std::string block = config::DumpOptions(d.lidar, "lidar") + config::DumpOptions(d.imu, "imu") +
                        config::DumpOptions(d.body, "body");
    os << Indented(block, "    ");
  }
  return os.str();
}

// The replay manifest (docs/replay.md) of the simulated logs: bags, ground
// truth, the sensors as simulated and the IMU time offset as if calibrated.
std::string Manifest(const Scenario& s, const Simulator& sim) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "# Replay manifest of the simulated run (written by swarmlio_sim).\n";
  os << "# swarmlio_replay --manifest=<this file> --output_dir=...\n";
  os << "name: " << s.options.name << "\n";
  os << "drones:\n";
  for (size_t i = 0; i < s.drones.size(); ++i) {
    const DroneConfig& d = s.drones[i];
    const Pose T = sim.T_W_G(static_cast<int>(i));
    const Eigen::Quaterniond q(T.R_W_b);
    os << "  - name: " << d.name << "\n";
    os << "    bag: " << d.name << ".bag\n";
    os << "    # G_i in the simulation world W (for plots)\n";
    os << "    p_G_in_W_m: " << Vec(T.p_b_in_W) << "\n";
    os << "    q_W_G_xyzw: [" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w() << "]\n";
    os << "    ground_truth: " << d.name << "_gt_tum.txt\n";
    os << Indented(config::DumpOptions(d.lidar.sensor, "lidar"), "    ");
    os << Indented(config::DumpOptions(d.imu.sensor, "imu"), "    ");
    os << "    odometry:\n";
    os << "      # IMU stamps later than the LiDAR's (the simulated offset, as if calibrated)\n";
    os << "      imu_time_offset_s: " << d.imu.time_offset_s << "\n";
  }
  return os.str();
}

int Main() {
  if (FLAGS_scenario.empty() || FLAGS_output_dir.empty()) {
    std::fprintf(stderr, "usage: swarmlio_sim --scenario=FILE --output_dir=DIR\n");
    return 2;
  }
  Scenario scenario;
  Status status = LoadScenario(FLAGS_scenario, &scenario);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  if (FLAGS_duration_s > 0) scenario.options.duration_s = FLAGS_duration_s;
  if (FLAGS_seed >= 0) scenario.options.seed = FLAGS_seed;
  if (FLAGS_threads > 0) scenario.options.num_threads = FLAGS_threads;
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_output_dir, ec);
  if (ec) {
    std::fprintf(stderr, "error: %s: %s\n", FLAGS_output_dir.c_str(), ec.message().c_str());
    return 1;
  }
  const std::filesystem::path dir(FLAGS_output_dir);
  std::vector<std::unique_ptr<DroneOutputWriter>> writers;
  std::vector<DroneSink*> sinks;
  for (const DroneConfig& d : scenario.drones) {
    std::unique_ptr<DroneOutputWriter> w;
    status = DroneOutputWriter::Open((dir / (d.name + ".bag")).string(),
                                     (dir / (d.name + "_gt_tum.txt")).string(),
                                     BagOptionsFor(scenario.bag, d.lidar.sensor), &w);
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.message().c_str());
      return 1;
    }
    sinks.push_back(w.get());
    writers.push_back(std::move(w));
  }
  const SimulationConfig config = scenario.simulation_config();
  const std::string name = scenario.options.name;
  Simulator sim(std::move(scenario.scene), scenario.drones, scenario.objects, config);
  {
    std::ofstream out(dir / "resolved_scenario.yaml");
    out << Resolved(scenario, sim);
    if (!out) {
      std::fprintf(stderr, "error: cannot write resolved_scenario.yaml\n");
      return 1;
    }
    std::ofstream manifest(dir / "swarm.yaml");
    manifest << Manifest(scenario, sim);
    if (!manifest) {
      std::fprintf(stderr, "error: cannot write swarm.yaml\n");
      return 1;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<DroneStats> stats;
  status = sim.Run(sinks, &stats);
  for (auto& w : writers) {
    const Status s = w->Close();
    if (status.ok()) status = s;
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  std::printf("scenario %s: %.1f s simulated in %.1f s wall (%.2fx real time, %d threads)\n",
              name.c_str(), config.duration_s, wall, config.duration_s / wall,
              config.num_threads);
  for (size_t i = 0; i < stats.size(); ++i) {
    const DroneStats& s = stats[i];
    std::printf("  %-8s imu %lld  scans %lld  points %lld  on-teammates %lld  tape %lld  "
                "scans-seeing-teammates %lld\n",
                sim.drones()[i].name.c_str(), static_cast<long long>(s.imu_samples),
                static_cast<long long>(s.scans), static_cast<long long>(s.points),
                static_cast<long long>(s.points_on_teammates),
                static_cast<long long>(s.tape_points),
                static_cast<long long>(s.scans_seeing_teammates));
  }
  return 0;
}

}  // namespace
}  // namespace swarmlio::sim

int main(int argc, char** argv) {
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  return swarmlio::sim::Main();
}
