// swarmlio_sim: runs a scenario and writes, per drone, a ROS1 bag
// (<name>.bag: /livox/lidar, /livox/imu, /ground_truth/pose) or with
// --bag_format=mcap / db3 a ROS 2 log of CDR messages (<name>.mcap, or a
// rosbag2 SQLite file <name>.db3), a TUM ground
// truth file in the drone's global frame (<name>_gt_tum.txt), and the resolved
// scenario (resolved_scenario.yaml: T_W_Gi, extrinsics, noise settings) and
// the replay manifest (swarm.yaml) for swarmlio_replay.
//
//   swarmlio_sim --scenario=configs/scenarios/indoor_3uav.yaml --output_dir=out
//                [--imperfections=realistic] [--bag_format=mcap|db3]
#include <gflags/gflags.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"

DEFINE_string(scenario, "", "scenario YAML file (configs/scenarios/*.yaml)");
DEFINE_string(output_dir, "", "output folder (created)");
DEFINE_string(bag_format,
              "",
              "override the scenario's bag.format: ros1 (<name>.bag), mcap (<name>.mcap) or db3 "
              "(<name>.db3, rosbag2 SQLite), the last two of ROS 2 CDR messages");
DEFINE_double(duration_s, 0.0, "override the scenario duration when > 0");
DEFINE_int64(seed, -1, "override the scenario seed when >= 0");
DEFINE_int32(threads, 0, "override the number of worker threads when > 0");
DEFINE_string(clock_offsets_s,
              "",
              "override the drones' clock offsets: one value per drone in scenario order, "
              "comma-separated [s] (e.g. 0,0.5,-0.5)");
DEFINE_string(imperfections,
              "",
              "sensor imperfections preset over the scenario's (ideal or realistic; the "
              "scenario's single-value imperfections keys still apply); empty: the scenario's");

namespace swarmlio::sim {
namespace {

// --bag_format over the scenario's bag.format; false (printed) if invalid.
bool ApplyBagFormatFlag(io::BagWriterOptions* bag) {
  if (FLAGS_bag_format.empty() || config::EnumFromString(FLAGS_bag_format, &bag->format)) {
    return true;
  }
  std::fprintf(stderr, "error: --bag_format '%s' is not one of %s\n", FLAGS_bag_format.c_str(),
               config::EnumChoices<io::BagFormat>().c_str());
  return false;
}

int Main() {
  if (FLAGS_scenario.empty() || FLAGS_output_dir.empty()) {
    std::fprintf(
        stderr,
        "usage: swarmlio_sim --scenario=FILE --output_dir=DIR [--imperfections=ideal|realistic]\n");
    return 2;
  }
  ScenarioOverrides overrides;
  if (!FLAGS_imperfections.empty()) {
    ImperfectionPreset preset;
    if (!config::EnumFromString(FLAGS_imperfections, &preset)) {
      std::fprintf(stderr, "error: --imperfections=%s: unknown preset (choices: %s)\n",
                   FLAGS_imperfections.c_str(), config::EnumChoices<ImperfectionPreset>().c_str());
      return 2;
    }
    overrides.imperfections = preset;
  }
  Scenario scenario;
  Status status = LoadScenario(FLAGS_scenario, &scenario, overrides);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  if (!ApplyBagFormatFlag(&scenario.bag)) return 2;
  if (FLAGS_duration_s > 0) scenario.options.duration_s = FLAGS_duration_s;
  if (FLAGS_seed >= 0) scenario.options.seed = FLAGS_seed;
  if (FLAGS_threads > 0) scenario.options.num_threads = FLAGS_threads;
  if (!FLAGS_clock_offsets_s.empty()) {
    std::vector<double> offsets;
    std::stringstream list(FLAGS_clock_offsets_s);
    std::string item;
    while (std::getline(list, item, ',')) {
      char* end = nullptr;
      const double v = std::strtod(item.c_str(), &end);
      if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v) ||
          std::abs(v) > 1e6) {
        std::fprintf(stderr, "error: --clock_offsets_s: '%s' is not a clock offset in seconds\n",
                     item.c_str());
        return 2;
      }
      offsets.push_back(v);
    }
    if (offsets.size() != scenario.drones.size()) {
      std::fprintf(stderr, "error: --clock_offsets_s has %zu values, the scenario %zu drones\n",
                   offsets.size(), scenario.drones.size());
      return 2;
    }
    for (size_t i = 0; i < offsets.size(); ++i) scenario.drones[i].clock_offset_s = offsets[i];
  }
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_output_dir, ec);
  if (ec) {
    std::fprintf(stderr, "error: %s: %s\n", FLAGS_output_dir.c_str(), ec.message().c_str());
    return 1;
  }
  const std::filesystem::path dir(FLAGS_output_dir);
  std::vector<std::unique_ptr<DroneOutputWriter>> writers;
  std::vector<DroneSink*> sinks;
  std::vector<std::string> drone_names;
  for (const DroneConfig& d : scenario.drones) drone_names.push_back(d.name);
  for (const DroneConfig& d : scenario.drones) {
    std::unique_ptr<DroneOutputWriter> w;
    status = DroneOutputWriter::Open((dir / BagFileName(d.name, scenario.bag)).string(),
                                     (dir / (d.name + "_gt_tum.txt")).string(),
                                     BagOptionsFor(scenario.bag, d.lidar.sensor), &w);
    if (status.ok()) {
      status = w->WriteTeammateReturnsTo((dir / (d.name + "_teammate_returns.csv")).string(),
                                         drone_names);
    }
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
    out << ResolvedScenarioYaml(scenario, sim);
    if (!out) {
      std::fprintf(stderr, "error: cannot write resolved_scenario.yaml\n");
      return 1;
    }
    std::ofstream manifest(dir / "swarm.yaml");
    manifest << ReplayManifestYaml(scenario, sim);
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
  std::printf(
      "scenario %s: %.1f s simulated in %.1f s wall (%.2fx real time, %d threads, "
      "imperfections %s)\n",
      name.c_str(), config.duration_s, wall, config.duration_s / wall, config.num_threads,
      config::EnumToString(scenario.imperfections));
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
