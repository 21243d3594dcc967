#include "sweep_file.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "swarmlio/config/config_file.h"

namespace swarmlio::sweep {
namespace {

// [A-Za-z0-9_.-]+, not "." or "..". (Checked by hand: std::regex trips
// GCC 12's -Wmaybe-uninitialized in the -O1 sanitizer builds.)
bool IsSafeName(const std::string& s) {
  if (s.empty() || s == "." || s == "..") return false;
  for (const char c : s) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) return false;
  }
  return true;
}

// The number after the last "seed:" (spaces allowed) on a line that has one.
bool SeedOnLine(const std::string& line, long long* seed) {
  for (size_t at = line.rfind("seed:"); at != std::string::npos;
       at = at == 0 ? std::string::npos : line.rfind("seed:", at - 1)) {
    size_t i = at + 5;
    while (i < line.size() && line[i] == ' ') ++i;
    size_t end = i;
    while (end < line.size() && line[end] >= '0' && line[end] <= '9') ++end;
    if (end > i && end - i < 19) {
      *seed = std::stoll(line.substr(i, end - i));
      return true;
    }
  }
  return false;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string CheckSeeds(const std::vector<double>& values, const char* key) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i] != std::floor(values[i]) || values[i] < 0 || values[i] > 4e9) {
      return std::string(key) + "[" + std::to_string(i) + "]: not a seed (an integer in [0, 4e9])";
    }
  }
  return "";
}

std::string Resolve(const std::string& entry, const std::string& dir) {
  const std::filesystem::path p(entry);
  return (p.is_absolute() ? p : std::filesystem::path(dir) / p).lexically_normal().string();
}

}  // namespace

std::string VariantOptions::Validate() const {
  if (!IsSafeName(name)) return "name: '" + name + "' is not a folder name ([A-Za-z0-9_.-]+)";
  if (!imperfections.empty() && imperfections.front() != '{' && !IsSafeName(imperfections)) {
    return "imperfections: a preset name or a YAML flow map {...}";
  }
  return config::ValidateFields(*this);
}

std::string GridOptions::Validate() const {
  if (!IsSafeName(name)) return "name: '" + name + "' is not a folder name ([A-Za-z0-9_.-]+)";
  for (const std::string& mode : modes) {
    if (mode != "swarm" && mode != "single") return "modes: '" + mode + "' is not swarm or single";
  }
  if (!seed_offsets.empty() && !seeds.empty()) return "seeds: give seeds or seed_offsets, not both";
  if (!logs.empty() && !seed_offsets.empty()) {
    return "seed_offsets: logs have no file seed; give seeds (the network seeds)";
  }
  std::string invalid = CheckSeeds(seed_offsets, "seed_offsets");
  if (invalid.empty()) invalid = CheckSeeds(seeds, "seeds");
  return invalid.empty() ? config::ValidateFields(*this) : invalid;
}

std::string SweepFile::Validate() const { return config::ValidateFields(*this); }

std::string ScenarioPath(const std::string& entry, const std::string& sweep_dir,
                         const std::string& root) {
  if (EndsWith(entry, ".yaml")) return Resolve(entry, sweep_dir);
  return (std::filesystem::path(root) / "configs" / "scenarios" / (entry + ".yaml")).string();
}

std::string ScenarioName(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

// The same rule as the shell scripts: the first `seed: N` between the
// `scenario:` line and the next top-level key.
Status ScenarioFileSeed(const std::string& path, long long* seed) {
  std::ifstream in(path);
  if (!in) return Status::NotFound(path + ": cannot open the scenario file");
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("scenario:", 0) == 0) {
      inside = true;
    } else if (inside && !line.empty() && line[0] >= 'a' && line[0] <= 'z') {
      break;
    }
    if (inside && SeedOnLine(line, seed)) return Status::Ok();
  }
  *seed = -1;
  return Status::Ok();
}

namespace {

Status CheckInputs(const config::ConfigFile& file, const std::string& dir, const std::string& root,
                   SweepFile* sweep) {
  GridOptions& grid = sweep->sweep;
  if (grid.scenarios.empty() && grid.logs.empty()) {
    return file.KeyError("sweep.scenarios", "no scenarios and no logs: nothing to run");
  }
  if (grid.seeds.empty() && grid.seed_offsets.empty()) grid.seed_offsets = {0};
  if (grid.modes.empty()) return file.KeyError("sweep.modes", "no mode");
  for (size_t i = 0; i < grid.scenarios.size(); ++i) {
    const std::string path = ScenarioPath(grid.scenarios[i], dir, root);
    const std::string key = "sweep.scenarios[" + std::to_string(i) + "]";
    if (!std::filesystem::is_regular_file(path)) return file.KeyError(key, "no scenario file " + path);
    long long seed = -1;
    SWARMLIO_RETURN_IF_ERROR(ScenarioFileSeed(path, &seed));
    if (seed < 0 && grid.seeds.empty()) return file.KeyError(key, "no seed in " + path);
    grid.scenarios[i] = path;
  }
  if (!grid.report.empty()) {
    const std::string report = Resolve(grid.report, root);
    if (!std::filesystem::is_regular_file(report)) return file.KeyError("sweep.report", "no script " + report);
    grid.report = report;
  }
  for (size_t i = 0; i < grid.logs.size(); ++i) {
    const std::string path = Resolve(grid.logs[i], dir);
    if (!std::filesystem::is_regular_file(path)) {
      return file.KeyError("sweep.logs[" + std::to_string(i) + "]", "no manifest " + path);
    }
    grid.logs[i] = path;
  }
  return Status::Ok();
}

}  // namespace

Status LoadSweep(const std::string& path, const std::string& root, SweepFile* sweep) {
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Load(path, &file));
  SweepFile candidate;
  SWARMLIO_RETURN_IF_ERROR(file.Read("", &candidate));
  SWARMLIO_RETURN_IF_ERROR(file.CheckNoUnusedSections());
  if (!file.HasSection("sweep")) return file.KeyError("sweep", "missing section");
  const std::string dir = std::filesystem::path(path).parent_path().string();
  SWARMLIO_RETURN_IF_ERROR(CheckInputs(file, dir.empty() ? "." : dir, root, &candidate));
  if (candidate.variants.empty()) {
    VariantOptions baseline;
    baseline.name = "baseline";
    candidate.variants.push_back(baseline);
  }
  std::set<std::string> names;
  for (size_t i = 0; i < candidate.variants.size(); ++i) {
    if (!names.insert(candidate.variants[i].name).second) {
      return file.KeyError("variants[" + std::to_string(i) + "].name",
                           "duplicate variant '" + candidate.variants[i].name + "'");
    }
  }
  *sweep = std::move(candidate);
  return Status::Ok();
}

}  // namespace swarmlio::sweep
