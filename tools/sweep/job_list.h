// Expands a sweep (sweep_file.h) into job lists: one line per run, each a
// self-contained shell command (tools/sweep/run_one.sh with every setting on
// its line) that writes into its own folder, writes `done` last, and exits 0
// at once when `done` is there. The simulations come in a list of their own
// (one per scenario, seed and simulator setting, shared by the variants and
// modes that only change the replay), so an engine can run them first on
// every core; a run line still simulates by itself (under a lock) when its
// simulation is missing.
//
// Layout under the output folder OUT:
//   OUT/sims/<sim key>/<scenario>/seed<S>/       the simulation (sim/, <scenario>.yaml)
//   OUT/runs/<variant>/<scenario>/seed<S>/<mode>/ the replay's results folder + `done`
#pragma once

#include <string>
#include <vector>

#include "sweep_file.h"

namespace swarmlio::sweep {

struct Job {
  std::string variant;
  std::string scenario;  // scenario or log name
  long long seed = 0;
  std::string mode;      // swarm | single
  std::string run_dir;
  std::string command;   // the self-contained run line
};

struct JobLists {
  std::vector<std::string> sims;  // simulation lines (unique)
  std::vector<Job> runs;
};

struct ExpandOptions {
  std::string root;       // the source tree (tools/sweep/run_one.sh, configs/)
  std::string build_dir;  // the Release build with swarmlio_sim and swarmlio_replay
  std::string out_dir;    // OUT
  std::string runner;     // the per-run script; default <root>/tools/sweep/run_one.sh
};

/// Runs in the order variant, scenario/log, seed, mode.
Status Expand(const SweepFile& sweep, const ExpandOptions& options, JobLists* jobs);

/// The name of a recorded log: its manifest's folder for "swarm.yaml", else its stem.
std::string LogName(const std::string& manifest_path);

/// Single-quotes `s` for a POSIX shell.
std::string ShellQuote(const std::string& s);

}  // namespace swarmlio::sweep
