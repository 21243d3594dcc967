// swarmlio_sweep: the two steps of a sweep that are not scheduling
// (docs/sweeps.md). tools/sweep.sh drives it; GNU parallel or Slurm runs
// the job lists in between.
//
//   swarmlio_sweep expand --sweep configs/sweeps/scenarios.yaml --out OUT --root . --build build
//       writes OUT/sims.jobs and OUT/runs.jobs (one self-contained shell
//       command per line), OUT/runs.tsv (variant, scenario, seed, mode, folder),
//       OUT/name, OUT/report (the sweep's report script) and OUT/sweep.yaml
//   swarmlio_sweep aggregate --out OUT [--title NAME]
//       writes OUT/summary.tsv, OUT/summary.md, OUT/summary_<figure>.png
//
// Exit code: 0 on success, 1 on an error (printed, naming file:line: key for
// a bad sweep file), 2 on a usage error.
#include <gflags/gflags.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "aggregate.h"
#include "job_list.h"
#include "sweep_file.h"

DEFINE_string(sweep, "", "expand: the sweep file (YAML, docs/sweeps.md)");
DEFINE_string(out, "", "the sweep's output folder");
DEFINE_string(root, ".", "expand: the source tree (configs/scenarios, tools/sweep/run_one.sh)");
DEFINE_string(build, "build", "expand: the Release build with swarmlio_sim and swarmlio_replay");
DEFINE_string(runner, "", "expand: the per-run script (default <root>/tools/sweep/run_one.sh)");
DEFINE_string(title, "", "aggregate: the title of summary.md (default: the sweep's name)");

namespace swarmlio::sweep {
namespace {

std::string Absolute(const std::string& p) {
  return std::filesystem::absolute(p).lexically_normal().string();
}

Status WriteLines(const std::string& path, const std::vector<std::string>& lines) {
  std::ofstream out(path);
  for (const std::string& line : lines) out << line << '\n';
  return out ? Status::Ok() : Status::IoError(path + ": cannot write");
}

Status RunExpand() {
  if (FLAGS_sweep.empty() || FLAGS_out.empty()) return Status::InvalidArgument("expand needs --sweep and --out");
  SweepFile sweep;
  SWARMLIO_RETURN_IF_ERROR(LoadSweep(FLAGS_sweep, Absolute(FLAGS_root), &sweep));
  const ExpandOptions options{Absolute(FLAGS_root), Absolute(FLAGS_build), Absolute(FLAGS_out),
                              FLAGS_runner.empty() ? "" : Absolute(FLAGS_runner)};
  JobLists jobs;
  SWARMLIO_RETURN_IF_ERROR(Expand(sweep, options, &jobs));
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) return Status::IoError(options.out_dir + ": " + ec.message());
  std::vector<std::string> lines;
  std::vector<RunEntry> entries;
  for (const Job& j : jobs.runs) {
    lines.push_back(j.command);
    entries.push_back({j.variant, j.scenario, j.seed, j.mode, j.run_dir});
  }
  SWARMLIO_RETURN_IF_ERROR(WriteLines(options.out_dir + "/sims.jobs", jobs.sims));
  SWARMLIO_RETURN_IF_ERROR(WriteLines(options.out_dir + "/runs.jobs", lines));
  SWARMLIO_RETURN_IF_ERROR(WriteRunList(options.out_dir + "/runs.tsv", entries));
  SWARMLIO_RETURN_IF_ERROR(WriteLines(options.out_dir + "/name", {sweep.sweep.name}));
  SWARMLIO_RETURN_IF_ERROR(WriteLines(options.out_dir + "/report", {sweep.sweep.report}));
  // The sweep file as the reports name it: relative to the source tree when inside it.
  const std::string relative =
      std::filesystem::path(Absolute(FLAGS_sweep)).lexically_relative(options.root).string();
  SWARMLIO_RETURN_IF_ERROR(WriteLines(
      options.out_dir + "/sweep.file",
      {relative.empty() || relative.rfind("..", 0) == 0 ? Absolute(FLAGS_sweep) : relative}));
  if (!std::filesystem::equivalent(FLAGS_sweep, options.out_dir + "/sweep.yaml", ec)) {
    std::filesystem::copy_file(FLAGS_sweep, options.out_dir + "/sweep.yaml",
                             std::filesystem::copy_options::overwrite_existing, ec);
    if (ec) return Status::IoError(options.out_dir + "/sweep.yaml: " + ec.message());
  }
  std::printf("%s: %zu variants, %zu simulations, %zu runs in %s/{sims,runs}.jobs\n",
              FLAGS_sweep.c_str(), sweep.variants.size(), jobs.sims.size(), jobs.runs.size(),
              options.out_dir.c_str());
  return Status::Ok();
}

Status RunAggregate() {
  if (FLAGS_out.empty()) return Status::InvalidArgument("aggregate needs --out");
  std::vector<RunEntry> runs;
  SWARMLIO_RETURN_IF_ERROR(ReadRunList(FLAGS_out + "/runs.tsv", &runs));
  Summary summary;
  SWARMLIO_RETURN_IF_ERROR(Summarize(runs, &summary));
  std::string title = FLAGS_title;
  if (title.empty()) std::getline(std::ifstream(FLAGS_out + "/name"), title);
  SWARMLIO_RETURN_IF_ERROR(WriteSummaryTsv(summary, FLAGS_out + "/summary.tsv"));
  SWARMLIO_RETURN_IF_ERROR(WriteSummaryMarkdown(summary, title, FLAGS_out + "/summary.md"));
  SWARMLIO_RETURN_IF_ERROR(PlotSummary(summary, FLAGS_out));
  std::printf("%d runs finished, %zu not; wrote %s/summary.{tsv,md} and summary_*.png\n",
              summary.finished, summary.unfinished.size(), FLAGS_out.c_str());
  return Status::Ok();
}

}  // namespace
}  // namespace swarmlio::sweep

int main(int argc, char** argv) {
  gflags::SetUsageMessage("swarmlio_sweep {expand|aggregate} [flags]  (docs/sweeps.md)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  if (argc != 2) {
    std::fprintf(stderr, "usage: swarmlio_sweep {expand|aggregate} [flags]  (docs/sweeps.md)\n");
    return 2;
  }
  const std::string command = argv[1];
  swarmlio::Status status;
  if (command == "expand") {
    status = swarmlio::sweep::RunExpand();
  } else if (command == "aggregate") {
    status = swarmlio::sweep::RunAggregate();
  } else {
    std::fprintf(stderr, "unknown command '%s': expand or aggregate\n", command.c_str());
    return 2;
  }
  if (!status.ok()) {
    std::fprintf(stderr, "swarmlio_sweep %s: %s\n", command.c_str(), status.message().c_str());
    return 1;
  }
  return 0;
}
