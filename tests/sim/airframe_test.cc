// Airframes (drone_body.h) as a Mid-360 sees them from 4-5 m: returns per
// scan, their intensity and their spread about the body centre for each
// model; and the scenario key `body.model`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <numeric>
#include <string>
#include <tuple>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/sensor_preset.h"
#include "swarmlio/sim/drone_body.h"
#include "swarmlio/sim/lidar_model.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

constexpr double kHeightM = 1.5;

SimulatedLidarOptions Mid360() {
  SimulatedLidarOptions o;
  const Status status = config::LoadSensorPreset(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/livox_mid360.yaml", &o.sensor, nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  return o;
}

// A 20 x 16 x 4 m room (60 % walls) with a 90 % albedo panel on the wall
// behind the target, the brightest diffuse surface of the scene.
void BuildRoom(Scene* scene) {
  AddRoom(Eigen::Vector3d::Zero(), Eigen::Vector3d(20, 16, 4), 0.5, Material::Diffuse(60.0),
          /*ceiling=*/true, scene);
  scene->Add(
      Primitive::Rectangle(Eigen::Vector3d(9.99, 0, 1.5),
                           Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                           1.0, 2.0, Material::Diffuse(90.0)));
  scene->Build();
}

// Returns on the target, the observed drone, over a number of scans.
struct Observation {
  int scans = 0;
  std::vector<int> returns_per_scan;                  // all returns on the target
  std::vector<double> reflective_intensity;           // of the returns on its reflective parts
  std::vector<Eigen::Vector3d> reflective_offsets_m;  // their p_W - target origin in W
  std::vector<double> panel_intensity;                // returns on the 90 % panel
};

// The observer hovers at the origin with a Mid-360; the target flies small
// excitations with +-60 deg of yaw around (distance_m, 0, 1.5) m.
Observation Observe(const DroneBodyOptions& body,
                    double distance_m,
                    uint64_t seed,
                    int frames = 40,
                    double dz = 0.0) {
  Scene scene;
  BuildRoom(&scene);
  TrajectoryBuilder ob(Eigen::Vector3d(0, 0, kHeightM), 0.0, TrajectoryBuilderOptions(), seed);
  ob.Hover(frames * 0.1 + 1.0);
  const Trajectory observer = ob.Build(0.0, frames * 0.1 + 1.0);
  TrajectoryBuilder tb(Eigen::Vector3d(distance_m, 0, kHeightM + dz), M_PI,
                       TrajectoryBuilderOptions(), seed + 1);
  tb.Excite(frames * 0.1 + 1.0, Eigen::Vector3d(0.2, 0.2, 0.05), M_PI / 3, 1.0);
  const Trajectory target = tb.Build(0.0, frames * 0.1 + 1.0);
  std::vector<MovingObject> objects(2);
  objects[0].trajectory = &observer;
  objects[0].parts_b = MakeDroneBody(DroneBodyOptions());
  objects[1].trajectory = &target;
  objects[1].parts_b = MakeDroneBody(body);
  for (MovingObject& o : objects) o.Finalize();

  const SimulatedLidarOptions lidar_options = Mid360();
  LidarModel lidar(lidar_options, &observer, &scene, &objects, 0, seed + 2);
  const Eigen::Matrix3d R_imu_lidar = lidar.R_imu_lidar();
  Observation out;
  SimulatedScan scan;
  for (int64_t frame = 0; frame < frames; ++frame) {
    lidar.Scan(frame, &scan);
    int on_target = 0;
    for (const SimulatedPoint& p : scan.points) {
      if (p.object == -1 && p.primitive == static_cast<int>(scene.primitives().size()) - 1) {
        out.panel_intensity.push_back(p.reflectivity);
      }
      if (p.object != 1) continue;
      ++on_target;
      if (objects[1].parts_b[p.primitive].material().type == SurfaceType::kDiffuse) continue;
      const Pose T_W_b = observer.PoseAt(p.t_s);
      const Eigen::Vector3d p_W =
          T_W_b.R_W_b * (R_imu_lidar * p.p_in_lidar + lidar_options.sensor.p_lidar_in_imu_m) +
          T_W_b.p_b_in_W;
      out.reflective_intensity.push_back(p.reflectivity);
      out.reflective_offsets_m.push_back(p_W - target.PositionAt(p.t_s));
    }
    out.returns_per_scan.push_back(on_target);
    ++out.scans;
  }
  return out;
}

double Mean(const std::vector<int>& v) {
  double sum = 0.0;
  for (int x : v) sum += x;
  return v.empty() ? 0.0 : sum / v.size();
}

// Per-axis RMS of the horizontal offsets about the body centre, sqrt(mean(dx^2 + dy^2) / 2) [m].
double HorizontalSpread(const std::vector<Eigen::Vector3d>& offsets) {
  double sum = 0.0;
  for (const Eigen::Vector3d& d : offsets) sum += d.head<2>().squaredNorm();
  return offsets.empty() ? 0.0 : std::sqrt(sum / (2.0 * offsets.size()));
}

// RMS of the vertical offsets about the body centre [m].
double VerticalSpread(const std::vector<Eigen::Vector3d>& offsets) {
  double sum = 0.0;
  for (const Eigen::Vector3d& d : offsets) sum += d.z() * d.z();
  return offsets.empty() ? 0.0 : std::sqrt(sum / offsets.size());
}

// Tape intensities: the 10th percentile keeps 90 % of the tape; the
// fraction of the 90 % panel's returns at or above it (0: intensity separates them).
double PanelAboveTapeP10(const Observation& o) {
  std::vector<double> tape = o.reflective_intensity;
  std::sort(tape.begin(), tape.end());
  const double threshold = tape[tape.size() / 10];
  int above = 0;
  for (double i : o.panel_intensity) above += i >= threshold;
  return static_cast<double>(above) / o.panel_intensity.size();
}

// At 4.5 m from a Mid-360 at the same height a drone gets ~3 returns per
// scan (measured: 3.0 tape_band and dim_tape, 3.8 arm_tape, 2.2
// reflective_shell), ~16 at 2 m; bounds are 2-3x around the measured values.
constexpr double kDistanceM = 4.5;
constexpr uint64_t kSeed = 5;

TEST(Airframe, TapeBandAndDimTapeSameReturnsDimTapeAmongTheBrightScenery) {
  const Observation tape =
      Observe(DroneBodyOptions::ForModel(AirframeModel::kTapeBand), kDistanceM, kSeed);
  const Observation dim =
      Observe(DroneBodyOptions::ForModel(AirframeModel::kDimTape), kDistanceM, kSeed);
  // Same geometry: the same returns (measured 3.0 per scan, 0.88 on the tape).
  EXPECT_GT(Mean(tape.returns_per_scan), 1.2);
  EXPECT_LT(Mean(tape.returns_per_scan), 7.5);
  EXPECT_GT(tape.reflective_intensity.size(), 0.3 * tape.scans);
  EXPECT_LT(tape.reflective_intensity.size(), 2.6 * tape.scans);
  EXPECT_NEAR(Mean(dim.returns_per_scan), Mean(tape.returns_per_scan),
              0.1 * Mean(tape.returns_per_scan));
  EXPECT_NEAR(static_cast<double>(dim.reflective_intensity.size()),
              static_cast<double>(tape.reflective_intensity.size()),
              0.1 * tape.reflective_intensity.size());
  // Intensities: new tape 151-255 (measured 186-252), above the 90 % panel
  // (measured 123-141); the dim tape in 100-145, among the panel's.
  const auto [tape_min, tape_max] =
      std::minmax_element(tape.reflective_intensity.begin(), tape.reflective_intensity.end());
  const auto [dim_min, dim_max] =
      std::minmax_element(dim.reflective_intensity.begin(), dim.reflective_intensity.end());
  const auto [panel_min, panel_max] =
      std::minmax_element(tape.panel_intensity.begin(), tape.panel_intensity.end());
  EXPECT_GT(*panel_max, 120.0);
  EXPECT_LE(*panel_max, 150.0);
  EXPECT_GT(*tape_min, *panel_max);
  EXPECT_EQ(PanelAboveTapeP10(tape), 0.0);
  EXPECT_GE(*dim_min, 100.0);
  EXPECT_LE(*dim_max, 145.0);
  EXPECT_GE(*dim_max, *panel_min);
  // No threshold keeps 90 % of the dim tape and drops 90 % of the panel.
  EXPECT_GT(PanelAboveTapeP10(dim), 0.1);
}

TEST(Airframe, ArmTapeSpreadsWiderWithItsCentroidOffTheOrigin) {
  const DroneBodyOptions arm = DroneBodyOptions::ForModel(AirframeModel::kArmTape);
  const std::vector<Primitive> parts = MakeDroneBody(arm);
  EXPECT_LT((ReflectiveCentroidInBody(parts) - Eigen::Vector3d(0, 0, 0.015)).norm(), 1e-12);
  const Observation o = Observe(arm, kDistanceM, kSeed);
  const Observation band =
      Observe(DroneBodyOptions::ForModel(AirframeModel::kTapeBand), kDistanceM, kSeed);
  // Measured: 3.8 returns per scan, 0.95 on the tape; spread 0.18 m against 0.075 m.
  EXPECT_GT(Mean(o.returns_per_scan), 1.5);
  EXPECT_LT(Mean(o.returns_per_scan), 9.0);
  EXPECT_GT(o.reflective_intensity.size(), 0.3 * o.scans);
  EXPECT_LT(o.reflective_intensity.size(), 3.0 * o.scans);
  for (double i : o.reflective_intensity) EXPECT_GE(i, 151.0);
  EXPECT_GT(HorizontalSpread(o.reflective_offsets_m),
            1.8 * HorizontalSpread(band.reflective_offsets_m));
  EXPECT_LT(HorizontalSpread(o.reflective_offsets_m), 0.3);
  // The near arm ends: the returns' centroid lies towards the observer (measured 0.13 m).
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& d : o.reflective_offsets_m) centroid += d;
  centroid /= static_cast<double>(o.reflective_offsets_m.size());
  EXPECT_GT(centroid.head<2>().norm(), 0.04);
  EXPECT_LT(centroid.head<2>().norm(), 0.3);
  EXPECT_LT(centroid.x(), 0.0);  // the observer is at -x
}

TEST(Airframe, ReflectiveShellIsASparseScatterOfConstantHighIntensity) {
  const DroneBodyOptions shell = DroneBodyOptions::ForModel(AirframeModel::kReflectiveShell);
  EXPECT_LT(ReflectiveCentroidInBody(MakeDroneBody(shell)).norm(), 1e-12);
  // Measured: 2.2 returns per scan at 4.5 m, 12 at 2 m; spread 0.12 m
  // horizontally (per axis), 0.025 m vertically.
  for (const auto& [distance_m, min_returns, max_returns] :
       {std::tuple{kDistanceM, 1.0, 6.0}, std::tuple{2.0, 5.0, 30.0}}) {
    const Observation o = Observe(shell, distance_m, kSeed);
    EXPECT_GT(Mean(o.returns_per_scan), min_returns) << distance_m;
    EXPECT_LT(Mean(o.returns_per_scan), max_returns) << distance_m;
    ASSERT_EQ(o.reflective_intensity.size(),
              static_cast<size_t>(
                  std::accumulate(o.returns_per_scan.begin(), o.returns_per_scan.end(), 0)));
    for (double i : o.reflective_intensity) {
      EXPECT_GE(i, 236.0);
      EXPECT_LE(i, 255.0);
    }
    const auto [lo, hi] =
        std::minmax_element(o.reflective_intensity.begin(), o.reflective_intensity.end());
    EXPECT_LE(*lo, 240.0) << "intensities uniform in 236-255";
    EXPECT_GE(*hi, 251.0);
    EXPECT_GT(HorizontalSpread(o.reflective_offsets_m), 0.08) << distance_m;
    EXPECT_LT(HorizontalSpread(o.reflective_offsets_m), 0.2) << distance_m;
    EXPECT_GT(VerticalSpread(o.reflective_offsets_m), 0.01) << distance_m;
    EXPECT_LT(VerticalSpread(o.reflective_offsets_m), 0.05) << distance_m;
  }
}

// Fraction of the returns on the far half of the target (seen from the
// observer at -x): 0 for a solid surface, (1 - p) / (2 - p) for a lattice
// crossed twice.
double FarSideFraction(const Observation& o) {
  int far = 0;
  for (const Eigen::Vector3d& d : o.reflective_offsets_m) far += d.x() > 0.0;
  return static_cast<double>(far) / o.reflective_offsets_m.size();
}

TEST(Airframe, LatticeLetsRaysThroughWithItsReturnProbability) {
  DroneBodyOptions solid = DroneBodyOptions::ForModel(AirframeModel::kReflectiveShell);
  solid.shell_return_probability = 1.0;
  DroneBodyOptions lattice = solid;
  lattice.shell_return_probability = 0.5;
  const Observation a = Observe(solid, 2.0, kSeed);
  const Observation b = Observe(lattice, 2.0, kSeed);
  // A ray crossing the shell twice returns with 1 - (1 - p)^2 = 0.75 (measured 0.73).
  const double ratio = Mean(b.returns_per_scan) / Mean(a.returns_per_scan);
  EXPECT_GT(ratio, 0.6);
  EXPECT_LT(ratio, 0.9);
  EXPECT_LT(FarSideFraction(a), 0.05);
  EXPECT_GT(FarSideFraction(b), 0.2);  // 1/3 expected
  EXPECT_LT(FarSideFraction(b), 0.45);
  // Deterministic: the same seed gives the same points.
  const Observation again = Observe(lattice, 2.0, kSeed);
  EXPECT_EQ(again.returns_per_scan, b.returns_per_scan);
  EXPECT_EQ(again.reflective_intensity, b.reflective_intensity);
}

// `body: {model: ...}` starts from the model's defaults; the drone's other
// body keys are read over them and validated against them.
TEST(Airframe, ScenarioChoosesTheModelPerDrone) {
  const std::string yaml = std::string("scenario: {name: frames, duration_s: 1.0, seed: 61}\n") +
                           R"(drones:
  - name: plain
  - name: arms
    body: {model: arm_tape, arm_span_m: 0.7, core_size_m: [0.3, 0.2, 0.04]}
  - name: shell
    body: {model: reflective_shell, shell_return_probability: 1}
  - name: dim
    body:
      model: dim_tape
      tape_gain_percent: 80
)";
  Scenario s;
  const Status status = ParseScenario(yaml, "frames.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(s.drones.size(), 4u);
  const DroneBodyOptions& plain = s.drones[0].body;
  EXPECT_EQ(plain.model, AirframeModel::kTapeBand);
  EXPECT_EQ(plain.arm_span_m, DroneBodyOptions().arm_span_m);
  const DroneBodyOptions& arms = s.drones[1].body;
  EXPECT_EQ(arms.model, AirframeModel::kArmTape);
  EXPECT_EQ(arms.arm_span_m, 0.7);         // the override
  EXPECT_EQ(arms.core_size_m.z(), 0.04);   // valid: arm_tape has no band
  EXPECT_EQ(arms.arm_tape_fraction, 0.5);  // the model's default
  EXPECT_EQ(arms.tape_height_m, 0.0);
  EXPECT_EQ(s.drones[2].body.model, AirframeModel::kReflectiveShell);
  EXPECT_EQ(s.drones[2].body.shell_return_probability, 1.0);
  EXPECT_EQ(s.drones[2].body.shell_diameter_m, 0.35);
  EXPECT_EQ(s.drones[3].body.model, AirframeModel::kDimTape);
  EXPECT_EQ(s.drones[3].body.tape_gain_percent, 80.0);
  EXPECT_EQ(s.drones[3].body.tape_intensity_max, 145.0);

  // resolved_scenario.yaml names each drone's model and reads back to the same body.
  const std::vector<DroneConfig> drones = s.drones;
  Simulator sim(std::move(s.scene), s.drones, s.objects, s.simulation_config());
  config::ConfigFile resolved;
  ASSERT_TRUE(
      config::ConfigFile::Parse(ResolvedScenarioYaml(s, sim), "resolved.yaml", &resolved).ok());
  for (size_t i = 0; i < drones.size(); ++i) {
    DroneBodyOptions body;
    ASSERT_TRUE(resolved.Read(config::IndexKey("drones", i) + ".body", &body).ok());
    EXPECT_EQ(body.model, drones[i].body.model) << i;
    EXPECT_EQ(body.arm_span_m, drones[i].body.arm_span_m) << i;
    EXPECT_EQ(body.shell_return_probability, drones[i].body.shell_return_probability) << i;
  }
  // The centroid of the reflective parts: arm_tape's arm height, core_z / 8 (here 0.04 / 8 m).
  const std::string text = ResolvedScenarioYaml(s, sim);
  const std::string key = "p_reflective_centroid_in_b_m: [0, 0, ";
  const size_t second = text.find(key, text.find(key) + 1);
  ASSERT_NE(second, std::string::npos);
  EXPECT_NEAR(std::strtod(text.c_str() + second + key.size(), nullptr), 0.005, 1e-12);
}

TEST(Airframe, ScenarioErrorsNameTheKey) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const Case cases[] = {
      {"drones:\n  - name: a\n    body: {model: hexacopter}\n",
       "bad.yaml:3: drones[0].body.model: unknown value 'hexacopter' (choices: tape_band, "
       "arm_tape, reflective_shell, dim_tape)"},
      // Valid over tape_band's 0.15 m core, not over arm_tape's 0.12 m.
      {"drones:\n  - body: {model: arm_tape, tape_height_m: 0.13}\n",
       "bad.yaml:2: drones[0].body.tape_height_m: must not exceed core_size_m[2]"},
      {"drones:\n  - body: {model: reflective_shell, shell_return_probability: 0}\n",
       "drones[0].body.shell_return_probability: value 0 is out of range"},
      {"drones:\n  - body: {model: dim_tape, tape_intensity_min: 150}\n",
       "drones[0].body.tape_intensity_max: must be above tape_intensity_min"},
      {"drones:\n  - body: {model: arm_tape, arm_tape_fraction: 1.5}\n",
       "drones[0].body.arm_tape_fraction: value 1.5 is out of range"},
      {"drones:\n  - body: {modle: arm_tape}\n", "drones[0].body.modle"},
  };
  for (const Case& c : cases) {
    Scenario s;
    const Status status = ParseScenario(c.yaml, "bad.yaml", &s);
    ASSERT_FALSE(status.ok()) << c.yaml;
    EXPECT_NE(status.message().find(c.expected), std::string::npos) << status.message();
  }
  // The same tape height is valid on the default airframe.
  Scenario s;
  EXPECT_TRUE(ParseScenario("drones:\n  - body: {tape_height_m: 0.13}\n", "ok.yaml", &s).ok());
}

}  // namespace
}  // namespace swarmlio::sim
