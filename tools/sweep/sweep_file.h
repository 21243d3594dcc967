// The researcher's grid (docs/sweeps.md): which variants (option overrides on
// top of the base configuration), which scenarios or recorded logs, which
// seeds and which modes. Read from a small YAML file:
//
//   sweep:
//     name: scenarios
//     scenarios: [indoor_3uav, decoys]     # configs/scenarios/<name>.yaml
//     seed_offsets: [1000, 2000]           # added to each scenario's file seed
//     modes: [swarm, single]
//   variants:
//     - name: baseline
//     - name: window5
//       replay_args: [--estimator=window, --window_size=5]
//
// Every key is checked by config::ConfigFile (unknown keys, wrong types are
// errors naming file:line: key); LoadSweep adds the cross checks (a missing
// scenario file, duplicate variant names, no seeds).
#pragma once

#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"

namespace swarmlio::sweep {

/// One estimator or simulator variant: overrides over the base configuration.
struct VariantOptions {
  std::string name;                       // folder name of its runs
  std::vector<std::string> sim_args;      // extra swarmlio_sim flags
  std::string imperfections;              // preset name, or a YAML map appended to the scenario
  std::vector<std::string> replay_args;   // extra swarmlio_replay flags
  std::string overrides;                  // YAML over every drone (swarmlio_replay --drone_overrides)
  std::string network;                    // YAML of the `network:` section (--network_config)

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("name", name, FieldSpec::Doc("variant name: letters, digits, '_', '-', '.'"));
    v("sim_args", sim_args, FieldSpec::Doc("extra swarmlio_sim flags"));
    v("imperfections", imperfections,
      FieldSpec::Doc("simulator preset name, or a YAML map appended as `imperfections:`"));
    v("replay_args", replay_args, FieldSpec::Doc("extra swarmlio_replay flags"));
    v("overrides", overrides,
      FieldSpec::Doc("YAML map (odometry, imu, lidar, teammate, swarm) over every drone"));
    v("network", network, FieldSpec::Doc("YAML map of the replay's `network:` section"));
  }
  std::string Validate() const;
};

/// The grid's axes other than the variants.
struct GridOptions {
  std::string name = "sweep";
  std::vector<std::string> scenarios;     // configs/scenarios/<name>.yaml, or a path to a .yaml
  std::vector<std::string> logs;          // recorded runs: manifest paths (no simulation)
  std::vector<double> seed_offsets;       // scenario seeds: the file's seed + each offset
  std::vector<double> seeds;              // or absolute seeds (logs: the network seed)
  std::vector<std::string> modes{"swarm", "single"};
  std::string report;  // a script run as `<report> OUT` once every run finished

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("name", name, FieldSpec::Doc("name of the sweep (report titles)"));
    v("scenarios", scenarios, FieldSpec::Doc("scenario names (configs/scenarios/) or paths"));
    v("logs", logs, FieldSpec::Doc("manifests of recorded runs (docs/replay.md)"));
    v("seed_offsets", seed_offsets, FieldSpec::Doc("offsets added to each scenario's file seed"));
    v("seeds", seeds, FieldSpec::Doc("absolute seeds (scenario seed; network seed for logs)"));
    v("modes", modes, FieldSpec::Doc("swarm and/or single (single-agent ablation)"));
    v("report", report,
      FieldSpec::Doc("script (relative to the source tree) run as `<report> OUT` when all runs finished"));
  }
  std::string Validate() const;
};

struct SweepFile {
  GridOptions sweep;
  std::vector<VariantOptions> variants;

  template <class V>
  void VisitFields(V&& v) {
    v("sweep", sweep);
    v("variants", variants);
  }
  std::string Validate() const;
};

/// Reads and checks `path`. Scenario names resolve to
/// `<root>/configs/scenarios/<name>.yaml` (a name ending in .yaml is a path,
/// relative to the sweep file's folder); logs too. Without `variants:` the
/// sweep has one variant, "baseline". Errors name file:line: key.
Status LoadSweep(const std::string& path, const std::string& root, SweepFile* sweep);

/// The resolved scenario file of an entry of `sweep.scenarios`.
std::string ScenarioPath(const std::string& entry, const std::string& sweep_dir,
                         const std::string& root);

/// The scenario's name (file name without .yaml) and its seed in the file
/// (`seed:` in the `scenario:` section; -1 when absent).
std::string ScenarioName(const std::string& path);
Status ScenarioFileSeed(const std::string& path, long long* seed);

}  // namespace swarmlio::sweep
