// The simulator's truth of the returns each scan had on each teammate
// (DroneOutputWriter::WriteTeammateReturnsTo), which the replay uses to count
// the scans a teammate was in view: it must add up to the simulator's own
// count of returns on other drones' bodies, scan by scan.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {
namespace {

namespace fs = std::filesystem;

TEST(SimulatorOutput, TeammateReturnsAddUpToTheReturnsOnTeammates) {
  Scenario scenario;
  const std::string path = std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml";
  ASSERT_TRUE(LoadScenario(path, &scenario).ok());
  SimulationConfig config = scenario.simulation_config();
  config.duration_s = 1.5;  // the drones start 2-3 m apart, facing each other
  const fs::path dir =
      fs::temp_directory_path() / ("swarmlio_sim_returns_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::vector<std::string> names;
  for (const DroneConfig& d : scenario.drones) names.push_back(d.name);
  std::vector<std::unique_ptr<DroneOutputWriter>> writers(names.size());
  std::vector<DroneSink*> sinks;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string stem = (dir / names[i]).string();
    ASSERT_TRUE(DroneOutputWriter::Open(
                    stem + ".bag", stem + ".tum",
                    BagOptionsFor(scenario.bag, scenario.drones[i].lidar.sensor), &writers[i])
                    .ok());
    ASSERT_TRUE(writers[i]->WriteTeammateReturnsTo(stem + "_returns.csv", names).ok());
    sinks.push_back(writers[i].get());
  }
  Simulator simulator(std::move(scenario.scene), scenario.drones, scenario.objects, config);
  std::vector<DroneStats> stats;
  ASSERT_TRUE(simulator.Run(sinks, &stats).ok());
  for (auto& w : writers) ASSERT_TRUE(w->Close().ok());

  for (size_t i = 0; i < names.size(); ++i) {
    SCOPED_TRACE(names[i]);
    std::ifstream in((dir / (names[i] + "_returns.csv")).string());
    std::string line;
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line, "scan_stamp_s,scan_end_s,teammate,returns");
    int64_t total = 0;
    std::set<std::string> scans;
    std::map<std::string, int> per_teammate;
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string start, end, teammate, returns;
      ASSERT_TRUE(std::getline(fields, start, ',') && std::getline(fields, end, ',') &&
                  std::getline(fields, teammate, ',') && std::getline(fields, returns));
      EXPECT_NE(teammate, names[i]) << "a drone's own body is not a teammate";
      EXPECT_LT(std::stod(start), std::stod(end));
      EXPECT_LT(std::stod(end) - std::stod(start), 0.11) << "one 10 Hz scan";
      EXPECT_GT(std::stoi(returns), 0);
      total += std::stoi(returns);
      per_teammate[teammate] += std::stoi(returns);
      scans.insert(start);
    }
    EXPECT_EQ(total, stats[i].points_on_teammates);
    EXPECT_EQ(static_cast<int64_t>(scans.size()), stats[i].scans_seeing_teammates);
    EXPECT_EQ(per_teammate.size(), names.size() - 1) << "every teammate is in view at the start";
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmlio::sim
