#include "sweep_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "sweep_test_util.h"

namespace swarmlio::sweep {
namespace {

using ::testing::HasSubstr;
using testing::FreshDir;
using testing::WriteFile;

Status LoadText(const std::string& text, SweepFile* sweep) {
  const std::string path = FreshDir("file") + "/s.yaml";
  WriteFile(path, text);
  return LoadSweep(path, SWARMLIO_SOURCE_DIR, sweep);
}

TEST(SweepFile, ReadsTheGridAndResolvesScenarios) {
  SweepFile sweep;
  ASSERT_TRUE(LoadText("sweep:\n  name: t\n  scenarios: [indoor_3uav]\n  seed_offsets: [0, 1000]\n"
                       "variants:\n  - name: a\n  - name: b\n    replay_args: [--window_size=5]\n",
                       &sweep).ok());
  ASSERT_EQ(sweep.sweep.scenarios.size(), 1u);
  EXPECT_THAT(sweep.sweep.scenarios[0], HasSubstr("configs/scenarios/indoor_3uav.yaml"));
  EXPECT_EQ(sweep.sweep.modes, (std::vector<std::string>{"swarm", "single"}));
  ASSERT_EQ(sweep.variants.size(), 2u);
  EXPECT_EQ(sweep.variants[1].replay_args, std::vector<std::string>{"--window_size=5"});
}

TEST(SweepFile, WithoutVariantsHasTheBaselineAndTheFileSeed) {
  SweepFile sweep;
  ASSERT_TRUE(LoadText("sweep: {scenarios: [decoys]}\n", &sweep).ok());
  ASSERT_EQ(sweep.variants.size(), 1u);
  EXPECT_EQ(sweep.variants[0].name, "baseline");
  EXPECT_EQ(sweep.sweep.seed_offsets, std::vector<double>{0});
}

TEST(SweepFile, ErrorsNameTheFileLineAndKey) {
  SweepFile sweep;
  Status s = LoadText("sweep:\n  scenarios: [indoor_3uav]\n  seeds_offsets: [1]\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("s.yaml:3: sweep.seeds_offsets"));
  s = LoadText("sweep:\n  scenarios: [indoor_3uav, no_such_scenario]\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("sweep.scenarios[1]: no scenario file"));
  s = LoadText("sweep: {scenarios: [decoys], modes: [swarm, solo]}\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("'solo' is not swarm or single"));
  s = LoadText("sweep: {scenarios: [decoys]}\nvariants: [{name: a}, {name: a}]\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("variants[1].name: duplicate variant 'a'"));
  s = LoadText("sweep: {scenarios: [decoys]}\nvariants: [{name: 'a/b'}]\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("not a folder name"));
  s = LoadText("sweep: {scenarios: [decoys], seeds: [1.5]}\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("seeds[0]: not a seed"));
  s = LoadText("sweep: {name: x}\n", &sweep);
  EXPECT_THAT(s.message(), HasSubstr("nothing to run"));
  s = LoadText("sweeps: {scenarios: [decoys]}\n", &sweep);
  EXPECT_FALSE(s.ok());
}

TEST(SweepFile, ReadsTheSeedOfAScenarioFile) {
  long long seed = 0;
  ASSERT_TRUE(ScenarioFileSeed(std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/airframes.yaml",
                               &seed).ok());
  EXPECT_EQ(seed, 61);
}

TEST(SweepFile, TheShippedSweepFilesLoad) {
  for (const char* name : {"scenarios", "window_comparison", "identification", "lossy_network",
                           "ablation_no_angular_noise"}) {
    SweepFile sweep;
    const Status s = LoadSweep(std::string(SWARMLIO_SOURCE_DIR) + "/configs/sweeps/" + name + ".yaml",
                               SWARMLIO_SOURCE_DIR, &sweep);
    EXPECT_TRUE(s.ok()) << name << ": " << s.message();
  }
}

}  // namespace
}  // namespace swarmlio::sweep
