#include "job_list.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <set>

namespace swarmlio::sweep {
namespace {

// A stable key of the simulator settings of a variant ("default" without any).
std::string SimKey(const VariantOptions& v) {
  if (v.sim_args.empty() && v.imperfections.empty()) return "default";
  std::string text = v.imperfections;
  for (const std::string& a : v.sim_args) text += '\n' + a;
  uint64_t h = 1469598103934665603ULL;  // FNV-1a 64
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ULL;
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string Flag(const std::string& name, const std::string& value) {
  return " --" + name + " " + ShellQuote(value);
}

std::string SimFlags(const VariantOptions& v, const std::string& scenario, long long seed,
                     const std::string& sim_dir) {
  std::string s = Flag("scenario", scenario) + Flag("seed", std::to_string(seed)) +
                  Flag("sim_dir", sim_dir);
  if (!v.imperfections.empty()) s += Flag("imperfections", v.imperfections);
  for (const std::string& a : v.sim_args) s += Flag("sim_arg", a);
  return s;
}

std::string ReplayFlags(const VariantOptions& v, const std::string& mode, const std::string& run_dir) {
  std::string s = Flag("mode", mode) + Flag("run_dir", run_dir);
  if (!v.overrides.empty()) s += Flag("overrides", v.overrides);
  if (!v.network.empty()) s += Flag("network", v.network);
  for (const std::string& a : v.replay_args) s += Flag("replay_arg", a);
  return s;
}

struct Input {
  std::string name;
  std::string path;
  bool is_log = false;
  std::vector<long long> seeds;
};

Status Inputs(const GridOptions& grid, std::vector<Input>* inputs) {
  for (const std::string& path : grid.scenarios) {
    Input in{ScenarioName(path), path, false, {}};
    long long file_seed = -1;
    SWARMLIO_RETURN_IF_ERROR(ScenarioFileSeed(path, &file_seed));
    for (double s : grid.seeds) in.seeds.push_back(static_cast<long long>(s));
    for (double o : grid.seed_offsets) in.seeds.push_back(file_seed + static_cast<long long>(o));
    inputs->push_back(in);
  }
  for (const std::string& path : grid.logs) {
    Input in{LogName(path), path, true, {}};
    for (double s : grid.seeds) in.seeds.push_back(static_cast<long long>(s));
    if (in.seeds.empty()) in.seeds.push_back(1);  // the NetworkOptions default seed
    inputs->push_back(in);
  }
  std::set<std::string> names;
  for (const Input& in : *inputs) {
    if (!names.insert(in.name).second) {
      return Status::InvalidArgument("two scenarios or logs named '" + in.name + "'");
    }
  }
  return Status::Ok();
}

}  // namespace

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string LogName(const std::string& manifest_path) {
  const std::filesystem::path p(manifest_path);
  if (p.stem() == "swarm" && p.has_parent_path() && !p.parent_path().filename().empty()) {
    return p.parent_path().filename().string();
  }
  return p.stem().string();
}

Status Expand(const SweepFile& sweep, const ExpandOptions& options, JobLists* jobs) {
  std::vector<Input> inputs;
  SWARMLIO_RETURN_IF_ERROR(Inputs(sweep.sweep, &inputs));
  const std::string runner =
      options.runner.empty() ? options.root + "/tools/sweep/run_one.sh" : options.runner;
  const std::string head = "bash " + ShellQuote(runner) + Flag("build", options.build_dir);
  std::set<std::string> sims_seen;
  for (const VariantOptions& v : sweep.variants) {
    for (const Input& in : inputs) {
      for (long long seed : in.seeds) {
        const std::string seed_dir = "/" + in.name + "/seed" + std::to_string(seed);
        const std::string sim_dir = options.out_dir + "/sims/" + SimKey(v) + seed_dir;
        const std::string input = in.is_log ? Flag("manifest", in.path) + Flag("network_seed", std::to_string(seed))
                                            : SimFlags(v, in.path, seed, sim_dir);
        if (!in.is_log && sims_seen.insert(sim_dir).second) {
          jobs->sims.push_back(head + " --sim_only" + input);
        }
        for (const std::string& mode : sweep.sweep.modes) {
          Job job{v.name, in.name, seed, mode, options.out_dir + "/runs/" + v.name + seed_dir + "/" + mode, ""};
          job.command = head + input + ReplayFlags(v, mode, job.run_dir);
          jobs->runs.push_back(job);
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace swarmlio::sweep
