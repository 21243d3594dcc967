#include "swarmlio/driver/manifest.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "swarmlio/config/dump_options.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"
#include "test_utils/given_calibration.h"

namespace swarmlio::driver {
namespace {

const std::string kPresets = std::string(SWARMLIO_SOURCE_DIR) + "/configs/";

TEST(Manifest, ReadsDronesPresetsAndOverrides) {
  const std::string yaml =
      "name: flight\n"
      "drones:\n"
      "  - name: a\n"
      "    bag: logs/a.bag\n"
      "    ground_truth: a_gt.txt\n"
      "    sensor_preset: " + kPresets + "livox_avia.yaml\n"
      "    lidar: {blind_range_m: 1.5}\n"
      "    imu: {acceleration_unit: g}\n"
      "    odometry: {imu_time_offset_s: 0.002, experimental: {association: {num_neighbors: 6}}}\n"
      "  - name: b\n"
      "    bag: /abs/b.bag\n"
      "    sensor_preset: " + kPresets + "livox_mid360.yaml\n"
      "    bag_topics: {imu_topic: /mavros/imu/data}\n"
      "    start_offset_s: 20\n"
      "    odometry: {initialization: in_flight, experimental: {in_flight: {passes: 2}}}\n";
  SwarmManifest m;
  const Status status = ParseManifest(yaml, "/data/run/swarm.yaml", &m);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(m.drones.size(), 2u);
  EXPECT_EQ(m.name, "flight");
  EXPECT_EQ(m.drones[0].bag_path, "/data/run/logs/a.bag");
  EXPECT_EQ(m.drones[0].ground_truth_path, "/data/run/a_gt.txt");
  EXPECT_EQ(m.drones[0].lidar.type, LidarType::kLivoxAvia);
  EXPECT_EQ(m.drones[0].lidar.blind_range_m, 1.5);
  EXPECT_EQ(m.drones[0].odometry.imu_time_offset_s, 0.002);
  EXPECT_EQ(m.drones[0].odometry.association.num_neighbors, 6);
  // Sensor-dependent defaults survive the overrides.
  EXPECT_EQ(m.drones[0].odometry.map.leaf_size_m, 0.25);
  EXPECT_EQ(m.drones[0].odometry.imu_init.acceleration_unit,
            lio::AccelerationUnitSetting::kStandardGravity);
  EXPECT_EQ(m.drones[1].bag_path, "/abs/b.bag");
  EXPECT_EQ(m.drones[1].ground_truth_path, "");
  EXPECT_EQ(m.drones[1].bag.imu_topic, "/mavros/imu/data");
  EXPECT_EQ(m.drones[1].odometry.map.leaf_size_m, 0.3);
  EXPECT_EQ(m.drones[0].start_offset_s, 0.0);
  EXPECT_EQ(m.drones[0].odometry.initialization, lio::InitializationMode::kStatic);
  EXPECT_EQ(m.drones[1].start_offset_s, 20.0);
  EXPECT_EQ(m.drones[1].odometry.initialization, lio::InitializationMode::kInFlight);
  EXPECT_EQ(m.drones[1].odometry.in_flight.passes, 2);
}

TEST(Manifest, RejectsBadEntriesWithFileLineAndKey) {
  struct Bad {
    std::string yaml;
    std::string expect;
  };
  const Bad cases[] = {
      {"drones: []\n", "at least one drone"},
      {"drones:\n  - {name: a}\n", "bag"},
      {"drones:\n  - {name: a, bag: x.bag}\n  - {name: a, bag: y.bag}\n", "duplicate"},
      {"drones:\n  - {name: a, bag: x.bag, odometry: {min_scan_pointz: 3}}\n", "min_scan_pointz"},
      {"drones:\n  - {name: a, bag: x.bag, odometry: {experimental: {min_scan_points: -3}}}\n",
       "drones[0].odometry.experimental.min_scan_points: value -3 is out of range"},
      {"drones:\n  - {name: a, bag: x.bag, odometry: {min_scan_points: 3}}\n",
       "drones[0].odometry.min_scan_points: moved to "
       "drones[0].odometry.experimental.min_scan_points"},
      {"drones:\n  - {name: a, bag: x.bag, sensor_preset: /no/such.yaml}\n", "sensor_preset"},
      {"drones:\n  - {name: a, bag: x.bag, start_offset_s: -1}\n", "start_offset_s"},
      {"drones:\n  - {name: a, bag: x.bag, odometry: {initialization: flying}}\n",
       "initialization"},
      {"drones:\n  - {name: a, bag: x.bag, odometry: {experimental: {in_flight: {passes: 0}}}}\n",
       "odometry.experimental.in_flight.passes"},
  };
  for (const Bad& c : cases) {
    SwarmManifest m;
    const Status status = ParseManifest(c.yaml, "m.yaml", &m);
    EXPECT_FALSE(status.ok()) << c.yaml;
    EXPECT_NE(status.message().find(c.expect), std::string::npos) << status.message();
    EXPECT_NE(status.message().find("m.yaml"), std::string::npos) << status.message();
  }
}

TEST(Manifest, FromBags) {
  SwarmManifest m;
  ASSERT_TRUE(ManifestFromBags({"x.bag", "y.bag"}, kPresets + "livox_mid360.yaml", {}, &m).ok());
  ASSERT_EQ(m.drones.size(), 2u);
  EXPECT_EQ(m.drones[1].name, "uav2");
  EXPECT_EQ(m.drones[1].lidar.type, LidarType::kLivoxMid360);
  EXPECT_FALSE(ManifestFromBags({}, "", {}, &m).ok());
  EXPECT_FALSE(ManifestFromBags({"x.bag"}, "", {"a", "b"}, &m).ok());
  EXPECT_FALSE(ManifestFromBags({"x.bag", "y.bag"}, "", {"a", "a"}, &m).ok());
}

TEST(Manifest, KeyGroundTruthFrame) {
  SwarmManifest manifest;
  const Status status = ParseManifest(
      "name: x\ndrones:\n  - {name: a, bag: a.bag, ground_truth_frame: G}\n"
      "  - {name: b, bag: b.bag, ground_truth_frame: other}\n  - {name: c, bag: c.bag}\n",
      "/tmp/m.yaml", &manifest);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(manifest.drones[0].ground_truth_frame, eval::GroundTruthFrame::kG);
  EXPECT_EQ(manifest.drones[1].ground_truth_frame, eval::GroundTruthFrame::kOther);
  EXPECT_EQ(manifest.drones[2].ground_truth_frame, eval::GroundTruthFrame::kAuto);
  EXPECT_FALSE(ParseManifest("name: x\ndrones:\n  - {name: a, bag: a.bag, ground_truth_frame: W}\n",
                             "/tmp/m.yaml", &manifest)
                   .ok());
}

TEST(Manifest, MarksSpinningLidars) {
  SwarmManifest manifest;
  const std::string preset = std::string(SWARMLIO_SOURCE_DIR) + "/configs/spinning_32.yaml";
  ASSERT_TRUE(ManifestFromBags({"a.bag"}, preset, {}, &manifest).ok());
  EXPECT_TRUE(manifest.drones[0].bag.spinning_lidar);
  ASSERT_TRUE(ParseManifest("name: x\ndrones:\n  - {name: a, bag: a.bag, sensor_preset: " + preset +
                                ", bag_topics: {spinning_lidar: false}}\n",
                            "/tmp/m.yaml", &manifest)
                  .ok());
  EXPECT_FALSE(manifest.drones[0].bag.spinning_lidar);
}

// The tests hand a simulated drone's estimator what swarmlio_sim's swarm.yaml
// does (test_utils/given_calibration.h): its sensors with the calibration the
// simulator reports as given (realistic: off the truth), the odometry
// defaults for them with the given IMU time offset.
TEST(Manifest, SimulatorsManifestIsWhatTheTestsHandTheEstimator) {
  sim::Scenario scenario;
  ASSERT_TRUE(sim::LoadScenario(kPresets + "scenarios/indoor_3uav.yaml", &scenario).ok());
  const std::vector<sim::DroneConfig> drones = scenario.drones;
  const sim::Simulator simulator(std::move(scenario.scene), drones, scenario.objects,
                                 scenario.simulation_config());
  SwarmManifest manifest;
  const Status status =
      ParseManifest(sim::ReplayManifestYaml(scenario, simulator), "/tmp/swarm.yaml", &manifest);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(manifest.drones.size(), drones.size());
  for (size_t i = 0; i < drones.size(); ++i) {
    SCOPED_TRACE(drones[i].name);
    const DroneInput given = swarmlio::testing::GivenDroneInput(drones[i]);
    const DroneInput& read = manifest.drones[i];
    EXPECT_EQ(read.name, given.name);
    EXPECT_EQ(config::DumpOptions(read.lidar), config::DumpOptions(given.lidar));
    EXPECT_EQ(config::DumpOptions(read.imu), config::DumpOptions(given.imu));
    EXPECT_EQ(config::DumpOptions(read.bag), config::DumpOptions(given.bag));
    EXPECT_EQ(config::DumpOptions(read.odometry), config::DumpOptions(given.odometry));
    EXPECT_NE(given.lidar.p_lidar_in_imu_m, drones[i].lidar.sensor.p_lidar_in_imu_m);
    EXPECT_NE(given.odometry.imu_time_offset_s, drones[i].imu.time_offset_s);
  }
}

}  // namespace
}  // namespace swarmlio::driver
