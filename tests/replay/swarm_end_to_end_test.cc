// Swarm end to end on wall_degenerate (36 s: the initialization flight, the
// Avia's turn to the wall and 12 s of wall-facing flight): simulated bags are
// replayed through the simulated network once in swarm mode and once as the
// single-agent ablation. Alone, the Avia facing the wall drifts along it
// (about a metre by then); with its teammates' mutual observations it stays
// within centimetres, and the observers lose nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/eval/consistency.h"
#include "swarmlio/net/network_options.h"
#include "swarmlio/replay/swarm_replay.h"
#include "test_utils/simulated_swarm.h"

namespace swarmlio::replay {
namespace {

namespace fs = std::filesystem;

class SwarmEndToEndTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("swarmlio_swarm_e2e_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    manifest_ = new driver::SwarmManifest();
    ASSERT_TRUE(swarmlio::testing::SimulateSwarm(
        std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/wall_degenerate.yaml",
        "wall_degenerate", 36.0, *dir_, manifest_));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete manifest_;
  }

  // Position RMSE of every drone against the bag's ground truth (same frame).
  static std::vector<double> Run(bool single_agent, std::vector<int>* identified,
                                 double latency_s = -1.0) {
    net::NetworkOptions network;
    if (latency_s >= 0.0) {
      network.default_link.latency_mean_s = latency_s;
      network.default_link.jitter_std_s = 0.0;
    }
    return Run(single_agent, network, identified);
  }

  static std::vector<double> Run(bool single_agent, const net::NetworkOptions& network,
                                 std::vector<int>* identified) {
    std::unique_ptr<SwarmReplay> run;
    EXPECT_TRUE(SwarmReplay::Create(*manifest_, &run).ok());
    ReplayOptions options;
    options.single_agent = single_agent;
    options.network = network;
    EXPECT_TRUE(run->Run(options).ok());
    std::vector<double> rmse;
    for (int i = 0; i < run->num_drones(); ++i) {
      eval::ConsistencyStats c;
      EXPECT_TRUE(eval::EvaluateConsistency(
                      UpdatedEstimate(run->drone(i).scans()),
                      eval::TrajectoryFromPoses(run->drone(i).bag_ground_truth()), 0.05, &c)
                      .ok());
      rmse.push_back(c.position_rmse_m);
      identified->push_back(static_cast<int>(run->drone(i).identifications().size()));
    }
    return rmse;
  }

  static fs::path* dir_;
  static driver::SwarmManifest* manifest_;
};

fs::path* SwarmEndToEndTest::dir_ = nullptr;
driver::SwarmManifest* SwarmEndToEndTest::manifest_ = nullptr;

TEST_F(SwarmEndToEndTest, TeammatesKeepTheWallFacingAviaFromDrifting) {
  std::vector<int> identified_swarm, identified_single;
  const std::vector<double> swarm = Run(false, &identified_swarm);
  const std::vector<double> single = Run(true, &identified_single);
  ASSERT_EQ(swarm.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    std::printf("[ figures  ] %s: position RMSE swarm %.4f m, single-agent %.4f m; "
                "identified %d / %d teammates\n",
                manifest_->drones[i].name.c_str(), swarm[i], single[i], identified_swarm[i],
                identified_single[i]);
    EXPECT_EQ(identified_swarm[i], 2);
    EXPECT_EQ(identified_single[i], 2);
  }
  // uav1 (Avia) drifts alone, not with its teammates. (Alone over 0.2 m
  // before the noisy-plane projection, 0.19 m with it (lio.md "Noisy map
  // planes"); with teammates 0.025 m. With the given calibration instead of
  // the true one (Release): 0.53 m alone, 0.039 m with teammates.)
  EXPECT_GT(single[0], 0.1);
  EXPECT_GT(single[0], 4.0 * swarm[0]);
  EXPECT_LT(swarm[0], 0.1);
  // The observers (Mid-360) are no worse than alone (+10 %, +1 mm of slack
  // for millimetre-level figures).
  for (int i = 1; i < 3; ++i) EXPECT_LT(swarm[i], 1.1 * single[i] + 0.001);
}

// Passive observations 0.4 s late (every message reaches the Avia four
// scans after it was made, within the default 0.5 s age limit): moved back
// to their time with the own IMU motion as a function of the current state
// (factors/passive_observation_factor.h), they still hold the Avia. With the
// motion treated as a known displacement (no attitude, bias and gravity
// columns) the Avia diverged (43 m on the full scenario; docs/swarm.md) and
// this 36 s run ends at 0.31 m. The bound is 0.10 m: the run is sensitive to
// small changes (0.028-0.062 m over the wire format's roundings and +-5 % on
// the velocity covariance), all far from the defect.
TEST_F(SwarmEndToEndTest, LateObservationsStillHoldTheWallFacingAvia) {
  std::vector<int> identified;
  const std::vector<double> late = Run(false, &identified, /*latency_s=*/0.4);
  ASSERT_EQ(late.size(), 3u);
  std::printf("[ figures  ] 0.4 s latency: position RMSE %.4f / %.4f / %.4f m\n", late[0],
              late[1], late[2]);
  EXPECT_LT(late[0], 0.10);
}

// The lossy network: 20 % of the packets lost, 100 ms latency (10 ms
// jitter), two network seeds. Every drone stays within 25 % of its lossless
// position RMSE (+3 mm for the centimetre-level observers), every pair is
// still identified, and the Avia is still held (alone it drifts 0.53 m:
// a defect that stops the fusion under loss fails here).
TEST_F(SwarmEndToEndTest, TwentyPercentLossAndATenthOfASecondKeepEveryDroneNearItsLosslessRun) {
  std::vector<int> identified_lossless;
  const std::vector<double> lossless = Run(false, net::NetworkOptions(), &identified_lossless);
  ASSERT_EQ(lossless.size(), 3u);
  for (const int seed : {1, 2}) {
    net::NetworkOptions network;
    network.seed = seed;
    network.default_link.loss_probability = 0.2;
    network.default_link.latency_mean_s = 0.1;
    network.default_link.jitter_std_s = 0.01;
    std::vector<int> identified;
    const std::vector<double> lossy = Run(false, network, &identified);
    ASSERT_EQ(lossy.size(), 3u);
    for (int i = 0; i < 3; ++i) {
      std::printf("[ figures  ] network seed %d, %s: position RMSE lossless %.4f m, 20 %% loss + "
                  "100 ms %.4f m (%+.1f %%)\n",
                  seed, manifest_->drones[i].name.c_str(), lossless[i], lossy[i],
                  100.0 * (lossy[i] / lossless[i] - 1.0));
      EXPECT_EQ(identified[i], 2) << seed << " " << i;
      EXPECT_LT(lossy[i], 1.25 * lossless[i] + 0.003) << seed << " " << i;
    }
    EXPECT_LT(lossy[0], 0.1);
  }
}

// Observations come again, in G_j, with the observer's next state message
// (swarm.repeat_observations). With every observation repeated ("all") and
// 30 % of the packets lost, the Avia still fuses about as many passive
// observations as on a lossless network (a repeat is lost too with 9 %),
// and on the lossless network every repeat is recognised as a duplicate
// (nothing fused twice). A defect in either direction moves the count by the
// loss rate: 30 % fewer without repeats, more than lossless when repeats are
// fused on top of the originals. The default repeats only the observations of
// a degenerate teammate: the Avia, in the wall-facing part of the flight.
TEST_F(SwarmEndToEndTest, RepeatedObservationsReplaceLostOnesAndNeverCountTwice) {
  using swarm::RepeatObservations;
  const auto run = [](double loss, RepeatObservations repeat) {
    driver::SwarmManifest manifest = *manifest_;
    for (driver::DroneInput& d : manifest.drones) {
      d.swarm.repeat_observations = repeat;
      // The repeats' own mechanism, without the byte budget's choices (which
      // drop repeats when the observers are at their budget: docs/swarm.md
      // "Broadcast budget"; the lossy-network figures in results.md are with it).
      d.swarm.broadcast_budget.max_bytes_per_s = 0.0;
    }
    std::unique_ptr<SwarmReplay> replay;
    EXPECT_TRUE(SwarmReplay::Create(manifest, &replay).ok());
    ReplayOptions options;
    options.network.default_link.loss_probability = loss;
    options.network.seed = 11;
    EXPECT_TRUE(replay->Run(options).ok());
    return replay->drone(0).estimator().counters();  // uav1, the Avia
  };
  const swarm::DroneEstimatorCounters lossless = run(0.0, RepeatObservations::kAll);
  const swarm::DroneEstimatorCounters lossy = run(0.3, RepeatObservations::kAll);
  const swarm::DroneEstimatorCounters bare = run(0.3, RepeatObservations::kNone);
  const swarm::DroneEstimatorCounters degenerate =
      run(0.3, RepeatObservations::kDegenerateTeammates);
  std::printf("[ figures  ] Avia passive observations: lossless %lld (%lld repeats seen twice); "
              "30 %% loss: %lld (%lld from repeats) repeating all, %lld (%lld) repeating those "
              "of degenerate teammates, %lld without repeats\n",
              static_cast<long long>(lossless.passive_fused),
              static_cast<long long>(lossless.repeats_duplicate),
              static_cast<long long>(lossy.passive_fused),
              static_cast<long long>(lossy.passive_repeated),
              static_cast<long long>(degenerate.passive_fused),
              static_cast<long long>(degenerate.passive_repeated),
              static_cast<long long>(bare.passive_fused));
  EXPECT_EQ(lossless.passive_repeated, 0);
  EXPECT_GT(lossless.repeats_duplicate, lossless.passive_fused / 2);
  EXPECT_EQ(bare.passive_repeated, 0);
  EXPECT_LT(bare.passive_fused, 0.8 * lossless.passive_fused);
  EXPECT_GT(lossy.passive_repeated, lossless.passive_fused / 10);
  EXPECT_GT(lossy.passive_fused, 0.85 * lossless.passive_fused);
  EXPECT_LE(lossy.passive_fused, lossless.passive_fused + 5);
  EXPECT_GT(degenerate.passive_repeated, 0);
  EXPECT_LT(degenerate.passive_repeated, lossy.passive_repeated);
}

// The same flight with the drones' clocks 0.5 s apart and drifting (the
// live-swarm fault of docs/network.md): each drone estimates its teammates'
// offsets from the timestamps and echoes in the state broadcasts (the
// default exchange) and maps their stamps onto its own clock,
// so the Avia is held as with agreeing clocks, and every offset is known
// within 0.5 ms. Taking the stamps as they come (synchronize_clocks off), the
// Avia's observations are half a second off; on indoor_3uav that tripled
// the Avia's error and lost a pair (docs/results.md).
TEST(SwarmClockTest, TeammateClockOffsetsAreEstimatedAndApplied) {
  const fs::path dir =
      fs::temp_directory_path() / ("swarmlio_swarm_clock_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  driver::SwarmManifest manifest;
  const std::vector<double> offsets_s = {0.0, 0.5, -0.5};
  const std::vector<double> drifts_ppm = {0.0, 30.0, -20.0};
  ASSERT_TRUE(swarmlio::testing::SimulateSwarm(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/wall_degenerate.yaml",
      "wall_degenerate_clocks", 36.0, dir, &manifest, [&](sim::Scenario* s) {
        for (size_t i = 0; i < s->drones.size(); ++i) {
          s->drones[i].clock_offset_s = offsets_s[i];
          s->drones[i].clock_drift_ppm = drifts_ppm[i];
        }
      }));
  std::unique_ptr<SwarmReplay> run;
  ASSERT_TRUE(SwarmReplay::Create(manifest, &run).ok());
  ASSERT_TRUE(run->Run(ReplayOptions()).ok());
  ASSERT_EQ(run->num_drones(), 3);
  for (int i = 0; i < 3; ++i) {
    const DroneRunner& d = run->drone(i);
    EXPECT_EQ(d.identifications().size(), 2u) << d.input().name;
    ASSERT_FALSE(d.scans().empty());
    const int64_t t_last = d.scans().back().ego.stamp_ns;
    const net::ClockSync* sync = d.estimator().clock_sync();
    ASSERT_NE(sync, nullptr);
    for (int j = 0; j < 3; ++j) {
      if (j == i) continue;
      const int64_t truth_ns =
          manifest.drones[j].true_clock.ToDrone(manifest.drones[i].true_clock.ToTrue(t_last)) -
          t_last;
      const net::ClockOffsetEstimate estimate = sync->Estimate(j, t_last);
      ASSERT_TRUE(estimate.valid) << i << " -> " << j;
      std::printf("[ figures  ] %s -> %s: clock offset %.4f s, error %.3f ms\n",
                  d.input().name.c_str(), manifest.drones[j].name.c_str(), 1e-9 * truth_ns,
                  1e-6 * static_cast<double>(estimate.offset_ns - truth_ns));
      // Measured within 0.21 ms (0.29 ms with the true calibration).
      EXPECT_LT(std::abs(estimate.offset_ns - truth_ns), 500'000) << i << " -> " << j;
    }
  }
  eval::ConsistencyStats avia;
  ASSERT_TRUE(eval::EvaluateConsistency(UpdatedEstimate(run->drone(0).scans()),
                                        eval::TrajectoryFromPoses(run->drone(0).bag_ground_truth()),
                                        0.05, &avia)
                  .ok());
  std::printf("[ figures  ] wall-facing Avia with clocks 0.5 s apart: position RMSE %.4f m\n",
              avia.position_rmse_m);
  EXPECT_LT(avia.position_rmse_m, 0.1);  // measured 0.041 m (0.027 m with the true calibration)
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace swarmlio::replay
