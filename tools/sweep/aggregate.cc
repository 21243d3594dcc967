#include "aggregate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <tuple>

#include "swarmlio/eval/plots.h"

namespace swarmlio::sweep {
namespace {

std::vector<std::string> SplitLine(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, sep);) {
    if (cell.size() >= 2 && cell.front() == '"' && cell.back() == '"') cell = cell.substr(1, cell.size() - 2);
    out.push_back(cell);
  }
  return out;
}

bool ParseNumber(const std::string& s, double* value) {
  if (s.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(*value);
}

// The seed values of one figure, keyed by variant, scenario, drone, figure, mode.
using Key = std::tuple<std::string, std::string, std::string, std::string, std::string>;

std::string Format(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

}  // namespace

const std::vector<std::string>& SummaryFigures() {
  static const std::vector<std::string> kFigures = {
      "ape_rmse_m", "rpe_rmse_m", "drift_percent", "nees_position", "nees_position_aligned",
      "time_median_ms", "time_p95_ms"};
  return kFigures;
}

Status ReadRunList(const std::string& path, std::vector<RunEntry>* runs) {
  std::ifstream in(path);
  if (!in) return Status::NotFound(path + ": cannot open the run list (run `expand` first)");
  std::string line;
  std::getline(in, line);  // header
  for (int n = 2; std::getline(in, line); ++n) {
    const std::vector<std::string> f = SplitLine(line, '\t');
    double seed = 0;
    if (f.size() != 5 || !ParseNumber(f[2], &seed)) {
      return Status::DataLoss(path + ":" + std::to_string(n) + ": not variant, scenario, seed, mode, dir");
    }
    runs->push_back({f[0], f[1], static_cast<long long>(seed), f[3], f[4]});
  }
  return Status::Ok();
}

Status WriteRunList(const std::string& path, const std::vector<RunEntry>& runs) {
  std::ofstream out(path);
  out << "variant\tscenario\tseed\tmode\trun_dir\n";
  for (const RunEntry& r : runs) {
    out << r.variant << '\t' << r.scenario << '\t' << r.seed << '\t' << r.mode << '\t' << r.run_dir << '\n';
  }
  return out ? Status::Ok() : Status::IoError(path + ": cannot write");
}

Status ReadMetricsCsv(const std::string& path, std::vector<std::string>* order,
                      std::map<std::string, std::map<std::string, double>>* values) {
  std::ifstream in(path);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) return Status::DataLoss(path + ": empty");
  const std::vector<std::string> header = SplitLine(line, ',');
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = SplitLine(line, ',');
    if (cells.empty()) continue;
    order->push_back(cells[0]);
    auto& row = (*values)[cells[0]];
    for (size_t c = 1; c < cells.size() && c < header.size(); ++c) {
      double v = 0;
      if (ParseNumber(cells[c], &v)) row[header[c]] = v;
    }
  }
  return Status::Ok();
}

Status Summarize(const std::vector<RunEntry>& runs, Summary* summary) {
  std::map<Key, std::vector<double>> values;
  std::vector<Key> order;
  for (const RunEntry& run : runs) {
    if (std::find(summary->variants.begin(), summary->variants.end(), run.variant) ==
        summary->variants.end()) {
      summary->variants.push_back(run.variant);
    }
    if (!std::filesystem::exists(run.run_dir + "/done")) {
      summary->unfinished.push_back(run);
      continue;
    }
    ++summary->finished;
    std::vector<std::string> drones;
    std::map<std::string, std::map<std::string, double>> metrics;
    const Status status = ReadMetricsCsv(run.run_dir + "/metrics.csv", &drones, &metrics);
    if (!status.ok()) continue;  // a finished run without metrics (a failed replay): no values
    for (const std::string& drone : drones) {
      for (const std::string& figure : SummaryFigures()) {
        const auto it = metrics[drone].find(figure);
        if (it == metrics[drone].end()) continue;
        const Key key{run.variant, run.scenario, drone, figure, run.mode};
        if (values.find(key) == values.end()) order.push_back(key);
        values[key].push_back(it->second);
      }
    }
  }
  // Rows grouped by variant (sweep order), scenario and drone (first seen),
  // figure (SummaryFigures order), mode (swarm first).
  std::map<std::string, size_t> first_seen;
  for (const Key& key : order) {
    first_seen.emplace(std::get<1>(key), first_seen.size());
    first_seen.emplace(std::get<1>(key) + "\n" + std::get<2>(key), first_seen.size());
  }
  const auto rank = [&](const Key& k) {
    const auto& v = summary->variants;
    const auto& f = SummaryFigures();
    return std::make_tuple(std::find(v.begin(), v.end(), std::get<0>(k)) - v.begin(),
                           first_seen[std::get<1>(k)],
                           first_seen[std::get<1>(k) + "\n" + std::get<2>(k)],
                           std::find(f.begin(), f.end(), std::get<3>(k)) - f.begin(),
                           std::get<4>(k) == "swarm" ? 0 : 1);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](const Key& a, const Key& b) { return rank(a) < rank(b); });
  for (const Key& key : order) {
    summary->rows.push_back({std::get<0>(key), std::get<1>(key), std::get<2>(key), std::get<3>(key),
                             std::get<4>(key), ComputeSeedStats(values[key])});
  }
  return Status::Ok();
}

Status WriteSummaryTsv(const Summary& summary, const std::string& path) {
  std::ofstream out(path);
  out << "variant\tscenario\tdrone\tfigure\tmode\tn\tmean\tstd\tmin\tmax\tci95_lo\tci95_hi\n";
  for (const SummaryRow& r : summary.rows) {
    const SeedStats& s = r.stats;
    out << r.variant << '\t' << r.scenario << '\t' << r.drone << '\t' << r.figure << '\t' << r.mode
        << '\t' << s.n;
    for (double v : {s.mean, s.std, s.min, s.max, s.ci95_lo, s.ci95_hi}) out << '\t' << Format("%.9g", v);
    out << '\n';
  }
  return out ? Status::Ok() : Status::IoError(path + ": cannot write");
}

}  // namespace swarmlio::sweep
