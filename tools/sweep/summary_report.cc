// The human-readable side of aggregate.h: summary.md and the PNG figures.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <utility>

#include "aggregate.h"
#include "swarmlio/eval/plots.h"

namespace swarmlio::sweep {
namespace {

std::string Cell(const SeedStats* s) {
  if (s == nullptr || s->n == 0) return "n/a | | |";
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%.4g +- %.2g | %.4g-%.4g | [%.4g, %.4g] | %d", s->mean, s->std,
                s->min, s->max, s->ci95_lo, s->ci95_hi, s->n);
  return buf;
}

// The swarm and single rows of one variant, scenario, drone and figure.
struct Pair {
  const SeedStats* swarm = nullptr;
  const SeedStats* single = nullptr;
};

void WriteVariant(const Summary& summary, const std::string& variant, std::ofstream& out) {
  std::vector<std::pair<std::string, Pair>> pairs;  // "scenario | drone | figure" in row order
  for (const SummaryRow& r : summary.rows) {
    if (r.variant != variant) continue;
    const std::string label = r.scenario + " | " + r.drone + " | " + r.figure;
    if (pairs.empty() || pairs.back().first != label) pairs.push_back({label, Pair{}});
    (r.mode == "swarm" ? pairs.back().second.swarm : pairs.back().second.single) = &r.stats;
  }
  out << "\n## " << variant << "\n\n";
  if (pairs.empty()) {
    out << "(no finished runs)\n";
    return;
  }
  out << "| scenario | drone | figure | swarm mean +- std | min-max | 95 % CI | n "
         "| single mean +- std | min-max | 95 % CI | n |\n";
  out << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [label, p] : pairs) {
    out << "| " << label << " | " << Cell(p.swarm) << " | " << Cell(p.single) << " |\n";
  }
}

}  // namespace

Status WriteSummaryMarkdown(const Summary& summary, const std::string& title, const std::string& path) {
  std::ofstream out(path);
  out << "# Sweep " << title << "\n\n";
  out << "Per variant, scenario, drone and figure (metrics.csv of swarmlio_replay, docs/replay.md), "
         "over the seeds: mean +- sample std, min-max, the 95 % t-interval of the mean and the "
         "number of seeds; swarm mode next to the single-agent ablation. Per-scan time: "
         "time_median_ms, time_p95_ms [ms]. "
      << summary.finished << " runs finished, " << summary.unfinished.size() << " not.\n";
  for (const std::string& v : summary.variants) WriteVariant(summary, v, out);
  if (!summary.unfinished.empty()) {
    out << "\nUnfinished runs (no `done`):\n\n";
    for (const RunEntry& r : summary.unfinished) {
      out << "- " << r.variant << " " << r.scenario << " seed " << r.seed << " " << r.mode << "\n";
    }
  }
  return out ? Status::Ok() : Status::IoError(path + ": cannot write");
}

Status PlotSummary(const Summary& summary, const std::string& out_dir) {
  for (const std::string figure : {"ape_rmse_m", "time_median_ms"}) {
    std::vector<std::string> categories;  // scenario/drone
    std::map<std::string, size_t> index;
    std::map<std::string, eval::IntervalSeries> series;  // "variant mode"
    std::vector<std::string> series_order;
    for (const SummaryRow& r : summary.rows) {
      if (r.figure != figure) continue;
      const std::string cat = r.scenario + "/" + r.drone;
      if (index.emplace(cat, categories.size()).second) categories.push_back(cat);
      const std::string name = r.variant + " " + r.mode;
      if (series.find(name) == series.end()) series_order.push_back(name);
      series[name].name = name;
    }
    if (categories.empty()) continue;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (auto& [name, s] : series) s.mean = s.lo = s.hi = std::vector<double>(categories.size(), nan);
    for (const SummaryRow& r : summary.rows) {
      if (r.figure != figure) continue;
      eval::IntervalSeries& s = series[r.variant + " " + r.mode];
      const size_t i = index[r.scenario + "/" + r.drone];
      s.mean[i] = r.stats.mean;
      s.lo[i] = r.stats.ci95_lo;
      s.hi[i] = r.stats.ci95_hi;
    }
    std::vector<eval::IntervalSeries> ordered;
    for (const std::string& name : series_order) ordered.push_back(series[name]);
    std::string x_label = "scenario/drone:";
    for (size_t i = 0; i < categories.size() && i < 12; ++i) {
      x_label += " " + std::to_string(i) + " " + categories[i];
    }
    if (categories.size() > 12) x_label += " ... (summary.tsv)";
    eval::PlotOptions options;
    options.title = figure + ": mean and 95 % interval over seeds";
    SWARMLIO_RETURN_IF_ERROR(eval::PlotIntervals(ordered, x_label, figure, options,
                                                 out_dir + "/summary_" + figure + ".png"));
  }
  return Status::Ok();
}

}  // namespace swarmlio::sweep
