#include "job_list.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "sweep_test_util.h"

namespace swarmlio::sweep {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

SweepFile TwoByTwo() {
  SweepFile sweep;
  const std::string path = testing::FreshDir("jobs") + "/s.yaml";
  testing::WriteFile(path,
                     "sweep:\n  scenarios: [indoor_3uav, airframes]\n  seed_offsets: [1000, 2000]\n"
                     "variants:\n  - name: base\n  - name: k5\n    replay_args: [--window_size=5]\n"
                     "  - name: ideal\n    imperfections: ideal\n    overrides: \"{swarm: {fuse_active: false}}\"\n");
  EXPECT_TRUE(LoadSweep(path, SWARMLIO_SOURCE_DIR, &sweep).ok());
  return sweep;
}

TEST(JobList, OneRunPerVariantScenarioSeedAndMode) {
  JobLists jobs;
  ASSERT_TRUE(Expand(TwoByTwo(), {"/src", "/b", "/out", ""}, &jobs).ok());
  ASSERT_EQ(jobs.runs.size(), 3u * 2 * 2 * 2);
  const Job& first = jobs.runs[0];
  EXPECT_EQ(first.variant, "base");
  EXPECT_EQ(first.scenario, "indoor_3uav");
  EXPECT_EQ(first.seed, 1001);
  EXPECT_EQ(first.mode, "swarm");
  EXPECT_EQ(first.run_dir, "/out/runs/base/indoor_3uav/seed1001/swarm");
  EXPECT_EQ(jobs.runs[4].seed, 1061);  // airframes' file seed 61
  EXPECT_THAT(first.command, HasSubstr("bash '/src/tools/sweep/run_one.sh' --build '/b'"));
  EXPECT_THAT(first.command, HasSubstr("--sim_dir '/out/sims/default/indoor_3uav/seed1001'"));
  EXPECT_THAT(first.command, Not(HasSubstr("--single_agent")));
}

TEST(JobList, VariantsThatOnlyChangeTheReplayShareTheSimulation) {
  JobLists jobs;
  ASSERT_TRUE(Expand(TwoByTwo(), {"/src", "/b", "/out", ""}, &jobs).ok());
  // base and k5 share 4 simulations; ideal has 4 of its own.
  EXPECT_EQ(jobs.sims.size(), 8u);
  EXPECT_THAT(jobs.runs[8].command, HasSubstr("--replay_arg '--window_size=5'"));
  EXPECT_THAT(jobs.runs[8].command, HasSubstr("/out/sims/default/"));
  EXPECT_THAT(jobs.runs[16].command, HasSubstr("--imperfections 'ideal'"));
  EXPECT_THAT(jobs.runs[16].command, Not(HasSubstr("/out/sims/default/")));
  EXPECT_THAT(jobs.runs[16].command, HasSubstr("--overrides '{swarm: {fuse_active: false}}'"));
}

TEST(JobList, LogsRunWithoutSimulationOnTheirNetworkSeeds) {
  const std::string dir = testing::FreshDir("logs");
  testing::WriteFile(dir + "/flight3/swarm.yaml", "name: x\n");
  testing::WriteFile(dir + "/s.yaml", "sweep:\n  logs: [flight3/swarm.yaml]\n  seeds: [1, 2]\n  modes: [swarm]\n");
  SweepFile sweep;
  ASSERT_TRUE(LoadSweep(dir + "/s.yaml", SWARMLIO_SOURCE_DIR, &sweep).ok());
  JobLists jobs;
  ASSERT_TRUE(Expand(sweep, {"/src", "/b", "/out", "/stub.sh"}, &jobs).ok());
  EXPECT_TRUE(jobs.sims.empty());
  ASSERT_EQ(jobs.runs.size(), 2u);
  EXPECT_EQ(jobs.runs[1].run_dir, "/out/runs/baseline/flight3/seed2/swarm");
  EXPECT_THAT(jobs.runs[1].command, HasSubstr("bash '/stub.sh'"));
  EXPECT_THAT(jobs.runs[1].command, HasSubstr("--network_seed '2'"));
}

TEST(JobList, QuotesForTheShell) {
  EXPECT_EQ(ShellQuote("a b"), "'a b'");
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
}

}  // namespace
}  // namespace swarmlio::sweep
