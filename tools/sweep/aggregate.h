// Collects every finished run of a sweep (OUT/runs.tsv lists them, in the
// sweep file's order; a run counts once its folder has `done`) and reduces
// each figure of its metrics.csv over the seeds: one row per variant,
// scenario, drone, figure and mode (seed_stats.h). Writes OUT/summary.tsv
// (machine-readable), OUT/summary.md (one table per variant, swarm next to
// single-agent) and OUT/summary_<figure>.png (mean and 95 % interval per
// variant and mode).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "seed_stats.h"
#include "swarmlio/common/status.h"

namespace swarmlio::sweep {

/// One line of OUT/runs.tsv.
struct RunEntry {
  std::string variant;
  std::string scenario;
  long long seed = 0;
  std::string mode;
  std::string run_dir;
};

/// The figures reduced over the seeds: metrics.csv columns.
const std::vector<std::string>& SummaryFigures();

struct SummaryRow {
  std::string variant;
  std::string scenario;
  std::string drone;
  std::string figure;
  std::string mode;
  SeedStats stats;
};

struct Summary {
  std::vector<std::string> variants;   // in the sweep file's order
  std::vector<SummaryRow> rows;        // variant, scenario, drone, figure, mode order
  std::vector<RunEntry> unfinished;    // runs without `done`
  int finished = 0;
};

Status ReadRunList(const std::string& path, std::vector<RunEntry>* runs);
Status WriteRunList(const std::string& path, const std::vector<RunEntry>& runs);

/// One metrics.csv as drone -> column -> number (cells that are not numbers
/// are left out); drones in file order in `order`.
Status ReadMetricsCsv(const std::string& path, std::vector<std::string>* order,
                      std::map<std::string, std::map<std::string, double>>* values);

Status Summarize(const std::vector<RunEntry>& runs, Summary* summary);

Status WriteSummaryTsv(const Summary& summary, const std::string& path);
Status WriteSummaryMarkdown(const Summary& summary, const std::string& title,
                            const std::string& path);
/// OUT/summary_<figure>.png for the APE and the per-scan time.
Status PlotSummary(const Summary& summary, const std::string& out_dir);

}  // namespace swarmlio::sweep
