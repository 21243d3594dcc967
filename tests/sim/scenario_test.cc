#include "swarmlio/sim/scenario.h"

#include <gtest/gtest.h>

#include <functional>
#include <sstream>
#include <string>

#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {
namespace {

const std::string kConfigDir = std::string(SWARMLIO_SOURCE_DIR) + "/configs";

// `yaml` after a scenario section that points preset_dir at configs/.
std::string WithPresets(const std::string& yaml) {
  return "scenario: {name: small, duration_s: 1.0, seed: 3, preset_dir: " + kConfigDir + "}\n" +
         yaml;
}

const std::string kSmall = WithPresets(R"(
scene:
  arena: {size_m: [10, 8, 4]}
  primitives:
    - {type: cylinder, center_m: [1, 1, 0], radius_m: 0.3, height_m: 2}
drones:
  - name: a
    start_m: [0, 0, 0.1]
    sensor_preset: livox_mid360.yaml
    lidar: {points_per_second: 20000}
    plan: [{kind: hover, duration_s: 0.5}, {kind: takeoff, height_m: 1.0}]
  - name: b
    start_m: [2, 0, 0.1]
    start_yaw_deg: 90
    lidar: {points_per_second: 24000}
    plan: [{kind: hover, duration_s: 0.5}, {kind: excite, duration_s: 4}]
objects:
  - name: sign
    start_m: [-2, 0, 0]
    parts: [{type: rectangle, center_m: [0, 0, 1.5], size_m: [0.4, 0.4, 0], material: retro_reflective}]
    plan: [{kind: transit, target_m: [-2, 2, 0]}]
)");

// Hashes every record a drone emits.
class HashSink : public DroneSink {
 public:
  Status OnImu(const ImuSample& imu) override {
    Mix(imu.stamp_ns);
    for (int i = 0; i < 3; ++i) Mix(imu.angular_velocity_rad_s[i] + imu.linear_acceleration[i]);
    ++imu_count;
    return Status::Ok();
  }
  Status OnScan(const LidarScan& scan, int64_t record_time_ns) override {
    Mix(scan.stamp_ns);
    Mix(record_time_ns);
    for (const LidarPoint& p : scan.points) Mix(p.x + p.y + p.z + p.reflectivity + p.offset_time_s);
    ++scan_count;
    return Status::Ok();
  }
  Status OnGroundTruth(const PoseStamped& pose) override {
    if (gt_count == 0) first_gt = pose;
    Mix(pose.stamp_ns);
    ++gt_count;
    return Status::Ok();
  }
  void Mix(double v) { hash = hash * 1099511628211ULL ^ std::hash<double>()(v); }
  uint64_t hash = 14695981039346656037ULL;
  int imu_count = 0, scan_count = 0, gt_count = 0;
  PoseStamped first_gt;
};

TEST(Scenario, ParsesAndSimulatesDeterministically) {
  uint64_t reference[2] = {0, 0};
  for (int threads : {1, 2}) {
    Scenario s;
    ASSERT_TRUE(ParseScenario(kSmall, "small.yaml", &s).ok());
    ASSERT_EQ(s.drones.size(), 2u);
    ASSERT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(s.scene.primitives().size(), 7u);                         // 6 arena boxes + cylinder
    EXPECT_EQ(s.drones[0].lidar.sensor.type, LidarType::kLivoxMid360);  // from the preset
    EXPECT_EQ(s.drones[0].lidar.sensor.max_range_m, 70.0);
    EXPECT_EQ(s.drones[0].lidar.sensor.points_per_second, 20000);     // the override
    EXPECT_EQ(s.drones[1].lidar.sensor.type, LidarType::kLivoxAvia);  // no preset: defaults
    SimulationConfig config = s.simulation_config();
    config.num_threads = threads;
    Simulator sim(std::move(s.scene), s.drones, s.objects, config);
    HashSink sinks[2];
    std::vector<DroneStats> stats;
    ASSERT_TRUE(sim.Run({&sinks[0], &sinks[1]}, &stats).ok());
    EXPECT_EQ(sinks[0].imu_count, 200);
    EXPECT_EQ(sinks[0].scan_count, 10);
    EXPECT_EQ(sinks[0].gt_count, 100);
    EXPECT_EQ(sinks[0].first_gt.stamp_ns, 1000000000000LL);
    EXPECT_LT(sinks[1].first_gt.p_b_in_G.norm(), 1e-12);  // G_i = initial IMU frame
    EXPECT_NEAR(sinks[1].first_gt.q_G_b.w(), 1.0, 1e-12);
    EXPECT_NEAR(sim.T_W_G(1).p_b_in_W.x(), 2.0, 1e-12);
    for (int i = 0; i < 2; ++i) {
      if (threads == 1) reference[i] = sinks[i].hash;
      EXPECT_EQ(sinks[i].hash, reference[i]) << "drone " << i;
    }
  }
}

TEST(Scenario, ErrorsNameFileLineAndKey) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const Case cases[] = {
      {"drones: [{name: a, lidar: {blind_range_m: -1}}]",
       "bad.yaml:1: drones[0].lidar.blind_range_m"},
      {"drones: [{name: a, lidar: {type: velodyne}}]", "drones[0].lidar.type"},
      {"drones: [{name: a, plan: [{kind: hover, duraton_s: 3}]}]", "drones[0].plan[0]"},
      {"scene: {primitives: [{type: box, min_m: [0, 0, 0], max_m: [-1, 1, 1]}]}\ndrones: [{}]",
       "scene.primitives[0].max_m"},
      {"scenario: {duration_s: abc}\ndrones: [{}]", "scenario.duration_s"},
      {"unknown_section: 1", "unknown_section"},
      {"scenario: {name: x}", "drones: the scenario has no drones"},
      {"drones: [{name: a}, {name: a}]", "bad.yaml:1: drones[1].name: duplicate"},
      {"drones: {name: a}", "drones: expected a list"},
      {"drones:\n  - name: a\n  - name: b\n    imu: {acceleration_unit: gee}\n",
       "bad.yaml:4: drones[1].imu.acceleration_unit: unknown value 'gee' (choices: m_s2, g)"},
      {"drones:\n  - lidar: {dropout_probability: 2}\n",
       "bad.yaml:2: drones[0].lidar.dropout_probability: value 2 is out of range"},
      {"drones:\n  - lidar: {points_per_second: 30}\n",
       "drones[0].lidar.points_per_second: must be at least scan_rate_hz * num_lines"},
      {"drones: [{}]\nobjects:\n  - name: sign\n", "bad.yaml:3: objects[0].parts: needs at least"},
      {"drones: [{}]\nbag: {compression: lz4, lidar_format: pointcloud2}\n",
       "bad.yaml:2: bag.lidar_format: set per drone by its lidar.message_format"},
      {"drones:\n  - name: a\n    sensor_preset: no_such_preset.yaml\n",
       "bad.yaml:3: drones[0].sensor_preset: ../no_such_preset.yaml: config file not found"},
  };
  for (const Case& c : cases) {
    Scenario s;
    const Status status = ParseScenario(c.yaml, "bad.yaml", &s);
    ASSERT_FALSE(status.ok()) << c.yaml;
    EXPECT_NE(status.message().find("bad.yaml"), std::string::npos) << status.message();
    EXPECT_NE(status.message().find(c.expected), std::string::npos) << status.message();
  }
  Scenario s;
  EXPECT_EQ(LoadScenario("/nonexistent/x.yaml", &s).code(), Status::Code::kNotFound);
}

// A drone's keys are read over its preset, and the merged sensor is what is
// validated: a spinning preset with a non-ns time unit is valid (its format is
// PointCloud2) although it would not be over the Livox defaults.
TEST(Scenario, SensorPresetWithOverrides) {
  Scenario s;
  const Status status = ParseScenario(WithPresets(R"(
drones:
  - name: spin
    sensor_preset: spinning_32.yaml
    lidar: {timestamp_unit: us, dropout_probability: 0.2, reflectivity: {retro_noise_sigma: 1}}
    imu: {acceleration_unit: g, time_offset_s: 0.003}
  - name: plain
)"),
                                      "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  const DroneConfig& d = s.drones[0];
  EXPECT_EQ(d.lidar.sensor.type, LidarType::kSpinning);
  EXPECT_EQ(d.lidar.sensor.num_lines, 32);
  EXPECT_EQ(d.lidar.sensor.blind_range_m, 1.0);
  EXPECT_EQ(d.lidar.sensor.timestamp_unit, TimestampUnit::kMicrosecond);
  EXPECT_EQ(d.lidar.dropout_probability, 0.2);
  EXPECT_EQ(d.lidar.reflectivity.retro_noise_sigma, 1.0);
  EXPECT_EQ(d.lidar.reflectivity.diffuse_noise_sigma, ReflectivityOptions().diffuse_noise_sigma);
  EXPECT_EQ(d.imu.sensor.acceleration_unit, AccelerationUnit::kStandardGravity);
  EXPECT_EQ(d.imu.sensor.rate_hz, 200.0);
  EXPECT_EQ(d.imu.time_offset_s, 0.003);
  EXPECT_EQ(s.drones[1].lidar.sensor.type, LidarType::kLivoxAvia);
  EXPECT_EQ(s.drones[1].lidar.sensor.max_range_m, LidarOptions().max_range_m);

  const io::BagWriterOptions bag = BagOptionsFor(s.bag, d.lidar.sensor);
  EXPECT_EQ(bag.lidar_format, LidarMessageFormat::kPointCloud2);
  EXPECT_EQ(bag.point_time_unit, TimestampUnit::kMicrosecond);
  EXPECT_EQ(BagOptionsFor(s.bag, s.drones[1].lidar.sensor).lidar_format,
            LidarMessageFormat::kLivoxCustomMsg);

  // An override that breaks the merged sensor names the drone's key and line.
  const Status bad = ParseScenario(WithPresets(R"(
drones:
  - name: a
    sensor_preset: livox_mid360.yaml
    lidar:
      blind_range_m: 80
)"),
                                   "x.yaml", &s);
  EXPECT_NE(bad.message().find(
                "x.yaml:7: drones[0].lidar.blind_range_m: must be below max_range_m (80 >= 70)"),
            std::string::npos)
      << bad.message();
}

TEST(Scenario, BagOptionsFollowTheSensorDescription) {
  LidarOptions lidar;
  lidar.type = LidarType::kSpinning;
  lidar.message_format = LidarMessageFormat::kPointCloud2;
  io::BagWriterOptions base;
  base.compression = io::BagCompression::kLz4;
  for (const auto& [unit, name] : config::EnumTraits<TimestampUnit>::kNames) {
    lidar.timestamp_unit = unit;
    const io::BagWriterOptions options = BagOptionsFor(base, lidar);
    EXPECT_STREQ(config::EnumToString(options.point_time_unit), name);
    EXPECT_EQ(options.lidar_format, LidarMessageFormat::kPointCloud2);
    EXPECT_EQ(options.compression, io::BagCompression::kLz4);
  }
}

TEST(Scenario, GeneratorUsesSensorPresets) {
  Scenario s;
  const Status status =
      ParseScenario(WithPresets("generator: {num_drones: 3, num_pillars: 2, sensor_presets: "
                                "[livox_avia.yaml, spinning_32.yaml]}\n"),
                    "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(s.drones.size(), 3u);
  EXPECT_EQ(s.drones[0].lidar.sensor.type, LidarType::kLivoxAvia);
  EXPECT_EQ(s.drones[1].lidar.sensor.type, LidarType::kSpinning);
  EXPECT_EQ(s.drones[2].lidar.sensor.type, LidarType::kLivoxAvia);
  EXPECT_EQ(s.drones[0].lidar.sensor.p_lidar_in_imu_m.x(), 0.027709);  // preset extrinsic
  const Status missing = ParseScenario(
      WithPresets("generator:\n  num_drones: 1\n  sensor_presets: [a.yaml]\n"), "x.yaml", &s);
  EXPECT_NE(missing.message().find("x.yaml:4: generator.sensor_presets[0]: "), std::string::npos)
      << missing.message();
}

// A straight transit through a solid box is refused with the drone, the box
// and the time; the same transit above the box, or a box left of the path,
// loads. (exploration.yaml flew all three drones through boxes until this.)
TEST(Scenario, AFlightThroughASolidIsAnError) {
  auto yaml = [](double box_top_m, double box_y_m) {
    std::ostringstream os;
    os << "scenario: {name: small, duration_s: 20, seed: 3, preset_dir: " << kConfigDir << "}\n"
       << "scene:\n  primitives:\n    - {type: box, min_m: [4, " << box_y_m - 1 << ", 0], max_m: [6, "
       << box_y_m + 1 << ", " << box_top_m << "]}\n"
       << "    - {type: cylinder, center_m: [0, 5, 0], radius_m: 0.5, height_m: 3}\n"
       << "drones:\n  - name: scout\n    start_m: [0, 0, 0.1]\n"
       << "    plan: [{kind: takeoff, height_m: 2}, {kind: transit, target_m: [10, 0, 2]}]\n";
    return os.str();
  };
  Scenario s;
  Status status = ParseScenario(yaml(3.0, 0.0), "through.yaml", &s);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("drones[0].plan: the flight of 'scout' passes through a box "
                                  "spanning [4, -1, 0] to [6, 1, 3] m"),
            std::string::npos)
      << status.message();
  EXPECT_TRUE(ParseScenario(yaml(1.5, 0.0), "over.yaml", &s).ok());
  EXPECT_TRUE(ParseScenario(yaml(3.0, 3.0), "beside.yaml", &s).ok());
}

TEST(Scenario, ShippedScenariosLoad) {
  for (const char* name : {"indoor_3uav", "wall_degenerate", "corridor", "exploration", "decoys",
                           "swarm_40", "relay_3uav", "airframes"}) {
    Scenario s;
    const Status status =
        LoadScenario(std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/" + name + ".yaml", &s);
    EXPECT_TRUE(status.ok()) << name << ": " << status.message();
  }
}

}  // namespace
}  // namespace swarmlio::sim
