// SwarmReplay on simulated bags: the same logs and network seed give the
// same outputs bit for bit; the single-agent ablation fuses nothing but
// keeps messaging; listed scans are left out (a live run's dropped scans);
// bad inputs give clear errors. The swarm estimator's own
// end-to-end test is swarm_end_to_end_test.cc.
#include "swarmlio/replay/swarm_replay.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/replay/dropped_scans.h"

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
    drones_ = new std::vector<sim::DroneConfig>(scenario.drones);
    sim::Simulator simulator(std::move(scenario.scene), scenario.drones, scenario.objects, config);
    std::vector<sim::DroneStats> stats;
    ASSERT_TRUE(simulator.Run(sinks, &stats).ok());
    for (auto& w : writers) ASSERT_TRUE(w->Close().ok());
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete drones_;
  }

  // The bags with their sensor preset and the calibration the simulator
  // reports as given (with its error, not the truth).
  static driver::SwarmManifest Manifest() {
    driver::SwarmManifest m;
    EXPECT_TRUE(driver::ManifestFromBags({(*dir_ / "uav1.bag").string(), (*dir_ / "uav2.bag").string()},
                                 std::string(SWARMLIO_SOURCE_DIR) + "/configs/livox_mid360.yaml",
                                 {"uav1", "uav2"}, &m)
                    .ok());
    for (size_t i = 0; i < m.drones.size(); ++i) {
      const sim::SensorCalibration given = sim::GivenCalibration((*drones_)[i]);
      m.drones[i].lidar.R_imu_lidar = given.R_imu_lidar;
      m.drones[i].lidar.p_lidar_in_imu_m = given.p_lidar_in_imu_m;
      m.drones[i].odometry.imu_time_offset_s = given.imu_time_offset_s;
    }
    return m;
  }

  static std::unique_ptr<SwarmReplay> Run(const ReplayOptions& options) {
    std::unique_ptr<SwarmReplay> run;
    EXPECT_TRUE(SwarmReplay::Create(Manifest(), &run).ok());
    EXPECT_TRUE(run->Run(options).ok());
    return run;
  }

  static fs::path* dir_;
  static std::vector<sim::DroneConfig>* drones_;  // as simulated
};

fs::path* SwarmReplayTest::dir_ = nullptr;
std::vector<sim::DroneConfig>* SwarmReplayTest::drones_ = nullptr;

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
      ASSERT_EQ(sa[k].ego.stamp_ns, sb[k].ego.stamp_ns);
      ASSERT_EQ(sa[k].ego.state.p_b_in_G, sb[k].ego.state.p_b_in_G);  // bit for bit
      ASSERT_EQ(sa[k].ego.state.q_G_b.coeffs(), sb[k].ego.state.q_G_b.coeffs());
      ASSERT_EQ(sa[k].ego.covariance, sb[k].ego.covariance);
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
    for (const swarm::DroneOutput& r : alone->drone(i).scans()) {
      EXPECT_EQ(r.active_observations + r.passive_observations, 0);
      ASSERT_TRUE(r.ego.state.p_b_in_G.allFinite());
    }
  }
}

// The record stamps of the scans in a bag.
std::vector<int64_t> ScanStamps(const std::string& bag_path) {
  std::vector<int64_t> stamps;
  std::unique_ptr<io::BagReader> reader;
  EXPECT_TRUE(io::BagReader::Open(bag_path, io::BagReaderOptions(), &reader).ok());
  io::BagRecord record;
  bool has = true;
  while (reader && reader->Next(&record, &has).ok() && has) {
    if (record.scan() != nullptr) stamps.push_back(record.stamp_ns());
  }
  return stamps;
}

// A re-run of a live drone leaves out the scans the live run dropped: the
// listed scans are never processed, the states before them are unchanged.
TEST_F(SwarmReplayTest, LeavesOutTheListedScans) {
  const auto all = Run(ReplayOptions());
  const std::vector<int64_t> stamps = ScanStamps((*dir_ / "uav2.bag").string());
  ASSERT_GT(stamps.size(), 50u);
  ReplayOptions options;
  // Two scans after the static start, and a stamp of no scan (ignored).
  options.dropped_scans["uav2"] = {stamps[45], stamps[46], stamps[46] + 1};
  const auto fewer = Run(options);
  EXPECT_EQ(fewer->drone(1).skipped_scans(), 2);
  EXPECT_EQ(fewer->drone(0).skipped_scans(), 0);
  const std::vector<swarm::DroneOutput>& a = all->drone(1).scans();
  const std::vector<swarm::DroneOutput>& b = fewer->drone(1).scans();
  ASSERT_EQ(b.size() + 2, a.size());
  size_t same = 0;
  while (same < b.size() && b[same].ego.stamp_ns == a[same].ego.stamp_ns &&
         b[same].ego.state.p_b_in_G == a[same].ego.state.p_b_in_G) {
    ++same;
  }
  EXPECT_GT(same, 30u);  // the scans before the gap: identical
  EXPECT_LT(same, b.size());  // the gap: a scan ends where the dropped ones did not
  for (const swarm::DroneOutput& r : b) {
    EXPECT_NE(r.ego.stamp_ns, a[same].ego.stamp_ns) << "a dropped scan was processed";
  }

  ReplayOptions unknown;
  unknown.dropped_scans["uav9"] = {stamps[45]};
  std::unique_ptr<SwarmReplay> run;
  ASSERT_TRUE(SwarmReplay::Create(Manifest(), &run).ok());
  const Status status = run->Run(unknown);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("uav9"), std::string::npos) << status.message();
}

TEST_F(SwarmReplayTest, DroppedScansFileIsReadOrRefusedByLine) {
  const std::string path = (*dir_ / "uav1_dropped_scans.txt").string();
  std::ofstream(path) << kDroppedScansHeader << "1000000000 queue\n\n2500000000 backlog\n";
  std::vector<int64_t> stamps;
  ASSERT_TRUE(ReadDroppedScans(path, &stamps).ok());
  EXPECT_EQ(stamps, (std::vector<int64_t>{1000000000, 2500000000}));

  for (const char* bad : {"12 queue\n1.5 queue\n", "12 queue\n13 late\n", "12 queue\n13\n",
                          "12 queue\n13 queue extra\n"}) {
    SCOPED_TRACE(bad);
    std::ofstream(path) << kDroppedScansHeader << bad;
    std::vector<int64_t> none = {7};
    const Status status = ReadDroppedScans(path, &none);
    EXPECT_EQ(status.code(), Status::Code::kDataLoss);
    EXPECT_NE(status.message().find("uav1_dropped_scans.txt:3:"), std::string::npos)
        << status.message();
    EXPECT_EQ(none, std::vector<int64_t>{7});  // untouched
  }
  EXPECT_EQ(ReadDroppedScans((*dir_ / "none.txt").string(), &stamps).code(),
            Status::Code::kIoError);
}

TEST_F(SwarmReplayTest, BadInputsGiveClearErrors) {
  driver::SwarmManifest m = Manifest();
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
