// Test helper: simulates a scenario file into one bag and ground-truth file
// per drone under `dir` and fills the replay manifest that reads them back,
// as swarmlio_sim's swarm.yaml does: each drone's sensors with the
// calibration the simulator reports as given (not the truth) and default
// odometry options (given_calibration.h). Header-only; the test executable
// links swarmlio_sim and swarmlio_replay.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/driver/manifest.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"
#include "test_utils/given_calibration.h"

namespace swarmlio::testing {

/// `scenario_path` simulated for `duration_s` seconds with 2 threads;
/// `edit`, when given, changes the loaded scenario first; with `true_G_in_W`
/// each drone's true G in the simulation world fills R_W_G / p_G_in_W_m.
inline ::testing::AssertionResult SimulateSwarm(
    const std::string& scenario_path, const std::string& name, double duration_s,
    const std::filesystem::path& dir, driver::SwarmManifest* manifest,
    const std::function<void(sim::Scenario*)>& edit = nullptr, bool true_G_in_W = false) {
  sim::Scenario scenario;
  const Status loaded = sim::LoadScenario(scenario_path, &scenario);
  if (!loaded.ok()) return ::testing::AssertionFailure() << loaded.message();
  if (edit) edit(&scenario);
  sim::SimulationConfig config = scenario.simulation_config();
  config.duration_s = duration_s;
  config.num_threads = 2;
  std::vector<std::unique_ptr<sim::DroneOutputWriter>> writers(scenario.drones.size());
  std::vector<sim::DroneSink*> sinks;
  manifest->name = name;
  for (size_t i = 0; i < scenario.drones.size(); ++i) {
    const sim::DroneConfig& d = scenario.drones[i];
    const std::string stem = (dir / d.name).string();
    const Status opened =
        sim::DroneOutputWriter::Open(stem + ".bag", stem + "_gt.txt",
                                     sim::BagOptionsFor(scenario.bag, d.lidar.sensor), &writers[i]);
    if (!opened.ok()) return ::testing::AssertionFailure() << opened.message();
    sinks.push_back(writers[i].get());
    driver::DroneInput input = GivenDroneInput(d);
    input.bag_path = stem + ".bag";
    input.true_clock.offset_s = d.clock_offset_s;  // packet delivery only
    input.true_clock.drift_ppm = d.clock_drift_ppm;
    input.true_clock.origin_s = config.stamp_origin_s;
    manifest->drones.push_back(input);
  }
  sim::Simulator simulator(std::move(scenario.scene), scenario.drones, scenario.objects, config);
  if (true_G_in_W) {
    // The true G_i in the simulation world (the replay's swarm report uses it).
    for (size_t i = 0; i < manifest->drones.size(); ++i) {
      const sim::Pose T = simulator.T_W_G(static_cast<int>(i));
      manifest->drones[i].R_W_G = T.R_W_b;
      manifest->drones[i].p_G_in_W_m = T.p_b_in_W;
    }
  }
  std::vector<sim::DroneStats> stats;
  const Status ran = simulator.Run(sinks, &stats);
  if (!ran.ok()) return ::testing::AssertionFailure() << ran.message();
  for (auto& w : writers) {
    const Status closed = w->Close();
    if (!closed.ok()) return ::testing::AssertionFailure() << closed.message();
  }
  return ::testing::AssertionSuccess();
}

}  // namespace swarmlio::testing
