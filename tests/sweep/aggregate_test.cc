#include "aggregate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sweep_test_util.h"

namespace swarmlio::sweep {
namespace {

using ::testing::HasSubstr;

std::string Read(const std::string& path) {
  std::stringstream ss;
  ss << std::ifstream(path).rdbuf();
  return ss.str();
}

// Two seeds x two modes of one variant; the single run of seed 2 unfinished.
std::vector<RunEntry> MakeRuns(const std::string& dir) {
  std::vector<RunEntry> runs;
  for (int seed : {1, 2}) {
    for (const char* mode : {"swarm", "single"}) {
      const std::string run_dir = dir + "/runs/v/sc/seed" + std::to_string(seed) + "/" + mode;
      runs.push_back({"v", "sc", seed, mode, run_dir});
      const double ape = 0.01 * seed + (std::string(mode) == "single" ? 0.1 : 0.0);
      testing::WriteFile(run_dir + "/metrics.csv",
                         "drone,ape_rmse_m,nees_position_aligned,time_median_ms\nuav1," +
                             std::to_string(ape) + ",n/a (no rotation fixed),12.5\n");
      if (!(seed == 2 && std::string(mode) == "single")) testing::WriteFile(run_dir + "/done", "");
    }
  }
  return runs;
}

TEST(Aggregate, ReducesEachFigureOverTheFinishedSeeds) {
  const std::string dir = testing::FreshDir("agg");
  Summary summary;
  ASSERT_TRUE(Summarize(MakeRuns(dir), &summary).ok());
  EXPECT_EQ(summary.finished, 3);
  ASSERT_EQ(summary.unfinished.size(), 1u);
  EXPECT_EQ(summary.unfinished[0].mode, "single");
  // ape and time for swarm and single; the NEES cell is not a number.
  ASSERT_EQ(summary.rows.size(), 4u);
  const SummaryRow& ape_swarm = summary.rows[0];
  EXPECT_EQ(ape_swarm.figure, "ape_rmse_m");
  EXPECT_EQ(ape_swarm.mode, "swarm");
  EXPECT_EQ(ape_swarm.stats.n, 2);
  EXPECT_NEAR(ape_swarm.stats.mean, 0.015, 1e-9);
  EXPECT_NEAR(ape_swarm.stats.ci95_hi, 0.015 + 12.706 * 0.0070710678 / std::sqrt(2.0), 1e-6);
  EXPECT_EQ(summary.rows[1].mode, "single");
  EXPECT_EQ(summary.rows[1].stats.n, 1);
}

TEST(Aggregate, WritesTheTablesAndThePlot) {
  const std::string dir = testing::FreshDir("agg_out");
  const std::vector<RunEntry> runs = MakeRuns(dir);
  ASSERT_TRUE(WriteRunList(dir + "/runs.tsv", runs).ok());
  std::vector<RunEntry> read;
  ASSERT_TRUE(ReadRunList(dir + "/runs.tsv", &read).ok());
  ASSERT_EQ(read.size(), 4u);
  EXPECT_EQ(read[3].run_dir, runs[3].run_dir);
  Summary summary;
  ASSERT_TRUE(Summarize(read, &summary).ok());
  ASSERT_TRUE(WriteSummaryTsv(summary, dir + "/summary.tsv").ok());
  ASSERT_TRUE(WriteSummaryMarkdown(summary, "t", dir + "/summary.md").ok());
  ASSERT_TRUE(PlotSummary(summary, dir).ok());
  EXPECT_THAT(Read(dir + "/summary.tsv"), HasSubstr("v\tsc\tuav1\tape_rmse_m\tswarm\t2\t0.015\t"));
  const std::string md = Read(dir + "/summary.md");
  EXPECT_THAT(md, HasSubstr("## v"));
  EXPECT_THAT(md, HasSubstr("| sc | uav1 | ape_rmse_m | 0.015 +- 0.0071 | 0.01-0.02 |"));
  EXPECT_THAT(md, HasSubstr("- v sc seed 2 single"));
  EXPECT_TRUE(std::filesystem::file_size(dir + "/summary_ape_rmse_m.png") > 1000);
}

}  // namespace
}  // namespace swarmlio::sweep
