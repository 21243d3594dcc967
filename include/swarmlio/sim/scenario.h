// Scenario files (configs/scenarios/*.yaml): the scene, the drones with their
// flight plans and sensors, moving decoys, and run settings, read with
// config::ConfigFile. The schema is documented in docs/simulator.md. A drone's
// sensors may start from a sensor preset (`sensor_preset: livox_mid360.yaml`,
// the `lidar` and `imu` sections of configs/livox_mid360.yaml) that its own
// `lidar:` and `imu:` keys override. Every error names the file, the line when
// known, and the full key, e.g.
//   "configs/scenarios/x.yaml:14: drones[1].lidar.blind_range_m: value -1 is
//    out of range (must be >= 0 m)".
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/sim/imperfections.h"
#include "swarmlio/sim/scene.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {

/// Run settings (the `scenario:` section).
struct ScenarioOptions {
  std::string name = "unnamed";
  double duration_s = 60.0;
  int64_t seed = 1;
  double stamp_origin_s = 1000.0;
  double ground_truth_rate_hz = 100.0;
  int num_threads = 2;
  std::string preset_dir = "..";  // relative to the scenario file's folder

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("name", name, FieldSpec::Doc("scenario name"));
    v("duration_s", duration_s, FieldSpec::Positive("s", "simulated time").WithMax(3600));
    v("seed", seed, FieldSpec::AtLeast(0, "", "random seed"));
    v("stamp_origin_s", stamp_origin_s,
      FieldSpec::InRange(1.0, 4e9, "s", "stamp of true time 0 (ROS time)"));
    v("ground_truth_rate_hz", ground_truth_rate_hz,
      FieldSpec::Positive("Hz", "ground-truth pose rate").WithMax(1000));
    v("num_threads", num_threads, FieldSpec::InRange(1, 64, "", "worker threads"));
    v("preset_dir", preset_dir,
      FieldSpec::Doc("folder of the sensor presets, relative to the scenario file's folder"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// A parsed scenario, ready to simulate.
struct Scenario {
  ScenarioOptions options;
  io::BagWriterOptions bag;
  /// The imperfections preset the drones' sensors start from (each drone's
  /// resolved values are in its lidar.imperfections, imu.imperfections,
  /// clock_drift_ppm and calibration_error).
  ImperfectionPreset imperfections = ImperfectionPreset::kIdeal;
  Scene scene;
  std::vector<DroneConfig> drones;
  std::vector<MovingObjectConfig> objects;

  SimulationConfig simulation_config() const;
};

/// Settings from outside the scenario file (swarmlio_sim flags).
struct ScenarioOverrides {
  /// Replaces the file's imperfections preset; the file's single-value
  /// `imperfections:` keys and the drones' own keys still apply over it.
  std::optional<ImperfectionPreset> imperfections;
};

/// Loads and validates a scenario file.
Status LoadScenario(const std::string& path,
                    Scenario* scenario,
                    const ScenarioOverrides& overrides = ScenarioOverrides());
/// Same for YAML text; `name` stands for the file in messages and in
/// resolving `scenario.preset_dir` (relative to the folder of `name`).
Status ParseScenario(const std::string& yaml_text,
                     const std::string& name,
                     Scenario* scenario,
                     const ScenarioOverrides& overrides = ScenarioOverrides());

}  // namespace swarmlio::sim
