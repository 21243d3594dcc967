// SwarmReplay on simulated bags: the same logs and network seed give the
// same outputs bit for bit; the single-agent ablation fuses nothing but
// keeps messaging; bad inputs give clear errors. The swarm estimator's own
// end-to-end test is swarm_end_to_end_test.cc.
#include "swarmlio/replay/swarm_replay.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::replay {
namespace {

namespace fs = std::filesystem;

class SwarmReplayTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("swarmlio_replay_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    sim::Scenario scenario;
    ASSERT_TRUE(sim::LoadScenario(std::string(SWARMLIO_SOURCE_DIR) +
                                      "/configs/scenarios/indoor_3uav.yaml",
                                  &scenario)
                    .ok());
    sim::SimulationConfig config = scenario.simulation_config();
    config.duration_s = 6.0;
    config.num_threads = 1;
    // Two Mid-360 drones (same preset), so ManifestFromBags can describe them.
    scenario.drones.resize(2);
    std::vector<std::unique_ptr<sim::DroneOutputWriter>> writers(2);
    std::vector<sim::DroneSink*> sinks;
    for (int i = 0; i < 2; ++i) {
      const std::string stem = (*dir_ / scenario.drones[i].name).string();
      ASSERT_TRUE(sim::DroneOutputWriter::Open(
                      stem + ".bag", stem + "_gt.txt",
                      sim::BagOptionsFor(scenario.bag, scenario.drones[i].lidar.sensor), &writers[i])
                      .ok());
      sinks.push_back(writers[i].get());
    }
    sim::Simulator simulator(std::move(scenario.scene), scenario.drones, scenario.objects, config);
    std::vector<sim::DroneStats> stats;
    ASSERT_TRUE(simulator.Run(sinks, &stats).ok());
    for (auto& w : writers) ASSERT_TRUE(w->Close().ok());
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
  }

  static SwarmManifest Manifest() {
    SwarmManifest m;
    EXPECT_TRUE(ManifestFromBags({(*dir_ / "uav1.bag").string(), (*dir_ / "uav2.bag").string()},
                                 std::string(SWARMLIO_SOURCE_DIR) + "/configs/livox_mid360.yaml",
                                 {"uav1", "uav2"}, &m)
                    .ok());
    return m;
  }

  static std::unique_ptr<SwarmReplay> Run(const ReplayOptions& options) {
    std::unique_ptr<SwarmReplay> run;
    EXPECT_TRUE(SwarmReplay::Create(Manifest(), &run).ok());
    EXPECT_TRUE(run->Run(options).ok());
    return run;
  }

  static fs::path* dir_;
};

fs::path* SwarmReplayTest::dir_ = nullptr;

ReplayOptions LossyNetwork(int64_t seed) {
  ReplayOptions options;
  options.network.seed = seed;
  options.network.default_link.latency_mean_s = 0.02;
  options.network.default_link.jitter_std_s = 0.01;
  options.network.default_link.loss_probability = 0.2;
  options.network.default_link.duplicate_probability = 0.1;
  return options;
}

void ExpectSameEstimates(const SwarmReplay& a, const SwarmReplay& b) {
  ASSERT_EQ(a.num_drones(), b.num_drones());
  for (int i = 0; i < a.num_drones(); ++i) {
    const auto& sa = a.drone(i).scans();
    const auto& sb = b.drone(i).scans();
    ASSERT_EQ(sa.size(), sb.size());
    for (size_t k = 0; k < sa.size(); ++k) {
      ASSERT_EQ(sa[k].stamp_ns, sb[k].stamp_ns);
      ASSERT_EQ(sa[k].state.p_b_in_G, sb[k].state.p_b_in_G);  // bit for bit
      ASSERT_EQ(sa[k].state.q_G_b.coeffs(), sb[k].state.q_G_b.coeffs());
      ASSERT_EQ(sa[k].pose_covariance, sb[k].pose_covariance);
    }
  }
}

TEST_F(SwarmReplayTest, SameSeedGivesIdenticalResultsAndTraffic) {
  const auto a = Run(LossyNetwork(7));
  const auto b = Run(LossyNetwork(7));
  ExpectSameEstimates(*a, *b);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GT(a->drone(i).scans().size(), 15u);
    EXPECT_EQ(a->traffic(i).received, b->traffic(i).received);
    EXPECT_EQ(a->traffic(i).channel.duplicates, b->traffic(i).channel.duplicates);
    EXPECT_GT(a->traffic(i).sent, 0);
    // 20 % loss: fewer arrive than were sent by the other drone.
    EXPECT_LT(a->traffic(i).received, a->traffic(1 - i).sent);
    EXPECT_GT(a->traffic(i).received, a->traffic(1 - i).sent / 2);
  }
  const net::LinkStats la = a->LinkStats(0, 1), lb = b->LinkStats(0, 1);
  EXPECT_EQ(la.delivered, lb.delivered);
  EXPECT_EQ(la.dropped_loss, lb.dropped_loss);
  EXPECT_GT(la.dropped_loss, 0u);
  EXPECT_GT(la.duplicated, 0u);
}

// The single-agent ablation fuses no mutual observation, but its messages
// still flow (teammates are identified and reported from them).
TEST_F(SwarmReplayTest, SingleAgentAblationFusesNothingButKeepsMessaging) {
  ReplayOptions single = LossyNetwork(3);
  single.single_agent = true;
  const auto alone = Run(single);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GT(alone->traffic(i).sent, 0);
    EXPECT_GT(alone->traffic(i).received, 0);
    EXPECT_EQ(alone->drone(i).estimator().counters().active_fused, 0);
    EXPECT_EQ(alone->drone(i).estimator().counters().passive_fused, 0);
    for (const ScanRecord& r : alone->drone(i).scans()) {
      EXPECT_EQ(r.active_observations + r.passive_observations, 0);
      ASSERT_TRUE(r.state.p_b_in_G.allFinite());
    }
  }
}

TEST_F(SwarmReplayTest, BadInputsGiveClearErrors) {
  SwarmManifest m = Manifest();
  m.drones[1].bag_path = (*dir_ / "missing.bag").string();
  std::unique_ptr<SwarmReplay> run;
  Status status = SwarmReplay::Create(m, &run);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("uav2"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("missing.bag"), std::string::npos) << status.message();

  m = Manifest();
  m.drones[0].bag.imu_topic = "/no/such/topic";  // absent: found by type instead
  ASSERT_TRUE(SwarmReplay::Create(m, &run).ok());
  EXPECT_EQ(run->drone(0).reader().imu_topic(), "/livox/imu");
  m.drones[0].bag.imu_topic = "auto";
  m.drones[0].bag.lidar_topic = "/livox/imu";  // a topic of the wrong type stays an error
  status = SwarmReplay::Create(m, &run);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("lidar_topic '/livox/imu' has type sensor_msgs/Imu"),
            std::string::npos)
      << status.message();

  ASSERT_TRUE(SwarmReplay::Create(Manifest(), &run).ok());
  ReplayOptions options;
  options.network.default_link.loss_probability = 2.0;  // invalid
  EXPECT_EQ(run->Run(options).code(), Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::replay
