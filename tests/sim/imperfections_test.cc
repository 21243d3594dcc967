// The `imperfections:` section of a scenario (presets, overrides, errors),
// the calibration handed to the estimator (error magnitudes, swarm.yaml vs the
// truth in resolved_scenario.yaml) and the per-drone clock drift.
#include "swarmlio/sim/imperfections.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/dump_options.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;
const std::string kConfigDir = std::string(SWARMLIO_SOURCE_DIR) + "/configs";

// Two drones (a Mid-360 and an Avia) and `extra` YAML (from line 16 on);
// `lidar0` is added to drone a's lidar map, `drone0` to its keys.
std::string Scenario2(const std::string& extra,
                      const std::string& lidar0 = "",
                      const std::string& drone0 = "") {
  return "scenario: {name: two, duration_s: 1.0, seed: 3, preset_dir: " + kConfigDir + "}\n" +
         R"(scene:
  arena: {size_m: [10, 8, 4]}
drones:
  - name: a
    start_m: [0, 0, 0.1]
    sensor_preset: livox_mid360.yaml
    lidar: {points_per_second: 20000)" +
         lidar0 + "}" + drone0 + R"(
    plan: [{kind: hover, duration_s: 0.5}, {kind: takeoff, height_m: 1.0}]
  - name: b
    start_m: [2, 0, 0.1]
    sensor_preset: livox_avia.yaml
    lidar: {points_per_second: 24000}
    imu: {time_offset_s: 0.002}
    plan: [{kind: hover, duration_s: 0.5}, {kind: takeoff, height_m: 1.0}]
)" + extra;
}

template <class Options>
std::string Dump(const Options& o) {
  return config::DumpOptions(o);
}

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return so3::Log(Eigen::Matrix3d(a.transpose() * b)).norm() / kDeg;
}

TEST(Imperfections, DefaultIsRealistic) {
  Scenario s;
  Status status = ParseScenario(Scenario2(""), "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(s.imperfections, ImperfectionPreset::kRealistic);
  for (const DroneConfig& d : s.drones) {
    EXPECT_GT(d.lidar.imperfections.angular_noise_deg, 0.0);
    EXPECT_FALSE(d.calibration_error.rotation_rad.isZero(0.0));
  }
  // A map without `preset:` is the realistic preset with the keys over it.
  status = ParseScenario(Scenario2("imperfections: {clock: {drift_sigma_ppm: 3}}\n"), "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(s.imperfections, ImperfectionPreset::kRealistic);
}

TEST(Imperfections, IdealIsEveryEffectOff) {
  Scenario s;
  const Status status = ParseScenario(Scenario2("imperfections: ideal\n"), "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(s.imperfections, ImperfectionPreset::kIdeal);
  for (const DroneConfig& d : s.drones) {
    EXPECT_EQ(Dump(d.lidar.imperfections), Dump(LidarImperfectionOptions()));
    EXPECT_EQ(Dump(d.imu.imperfections), Dump(ImuImperfectionOptions()));
    EXPECT_EQ(d.clock_drift_ppm, 0.0);
    EXPECT_TRUE(d.calibration_error.rotation_rad.isZero(0.0));
    EXPECT_TRUE(d.calibration_error.translation_m.isZero(0.0));
    EXPECT_EQ(d.calibration_error.imu_time_offset_s, 0.0);
    const SensorCalibration given = GivenCalibration(d);
    EXPECT_EQ(given.R_imu_lidar, d.lidar.sensor.R_imu_lidar);
    EXPECT_EQ(given.p_lidar_in_imu_m, d.lidar.sensor.p_lidar_in_imu_m);
    EXPECT_EQ(given.imu_time_offset_s, d.imu.time_offset_s);
  }
}

// `imperfections: realistic`: LiDAR values per type (Mid-360 / Avia), IMU,
// calibration error and clock drift drawn per drone.
TEST(Imperfections, RealisticByNameFollowsTheLidarType) {
  Scenario s;
  const Status status = ParseScenario(Scenario2("imperfections: realistic\n"), "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(s.imperfections, ImperfectionPreset::kRealistic);
  ASSERT_EQ(s.drones.size(), 2u);
  EXPECT_EQ(Dump(s.drones[0].lidar.imperfections),
            Dump(RealisticLidarImperfections(LidarType::kLivoxMid360)));
  EXPECT_EQ(Dump(s.drones[1].lidar.imperfections),
            Dump(RealisticLidarImperfections(LidarType::kLivoxAvia)));
  EXPECT_EQ(s.drones[0].lidar.imperfections.angular_noise_deg, 0.15);
  EXPECT_EQ(s.drones[1].lidar.imperfections.angular_noise_deg, 0.05);
  EXPECT_EQ(s.drones[1].lidar.imperfections.beam_divergence_vertical_deg, 0.28);
  for (const DroneConfig& d : s.drones) {
    EXPECT_EQ(Dump(d.imu.imperfections), Dump(RealisticImuImperfections()));
    const double angle = d.calibration_error.rotation_rad.norm() / kDeg;
    EXPECT_GE(angle, 0.2);
    EXPECT_LE(angle, 0.5);
    EXPECT_GE(d.calibration_error.translation_m.norm(), 0.005);
    EXPECT_LE(d.calibration_error.translation_m.norm(), 0.010);
    EXPECT_GE(std::abs(d.calibration_error.imu_time_offset_s), 0.0005);
    EXPECT_LE(std::abs(d.calibration_error.imu_time_offset_s), 0.0015);
    EXPECT_NE(d.clock_drift_ppm, 0.0);
    EXPECT_LT(std::abs(d.clock_drift_ppm), 5.0 * RealisticClock().drift_sigma_ppm);
  }
  EXPECT_NE(s.drones[0].clock_drift_ppm, s.drones[1].clock_drift_ppm);
}

// Single values over the preset: the scenario's keys for every drone, a
// drone's own lidar.imperfections keys over those; a preset given from
// outside (swarmlio_sim --imperfections) replaces the file's preset only.
TEST(Imperfections, OverridesApplyOverThePreset) {
  const std::string keys = R"(imperfections:
  preset: realistic
  lidar: {mixed_pixel_probability: 0.2}
  imu: {timestamp_jitter_s: 0}
  clock: {drift_sigma_ppm: 0}
)";
  Scenario s;
  Status status = ParseScenario(
      Scenario2(keys, ", imperfections: {angular_noise_deg: 0.3}", "\n    clock_drift_ppm: 12"),
      "x.yaml", &s);
  ASSERT_TRUE(status.ok()) << status.message();
  const LidarImperfectionOptions& a = s.drones[0].lidar.imperfections;
  const LidarImperfectionOptions& b = s.drones[1].lidar.imperfections;
  EXPECT_EQ(a.angular_noise_deg, 0.3);                           // the drone's own key
  EXPECT_EQ(s.drones[0].lidar.sensor.points_per_second, 20000);  // its other lidar keys stay
  EXPECT_EQ(b.angular_noise_deg, 0.05);
  EXPECT_EQ(a.mixed_pixel_probability, 0.2);  // the scenario's key, both drones
  EXPECT_EQ(b.mixed_pixel_probability, 0.2);
  EXPECT_EQ(a.beam_divergence_horizontal_deg, 0.18);  // the rest from the preset
  EXPECT_EQ(b.beam_divergence_horizontal_deg, 0.03);
  EXPECT_EQ(s.drones[0].imu.imperfections.timestamp_jitter_s, 0.0);
  EXPECT_EQ(s.drones[0].imu.imperfections.gyro_lsb_rad_s,
            RealisticImuImperfections().gyro_lsb_rad_s);
  EXPECT_EQ(s.drones[0].clock_drift_ppm, 12.0);  // explicit only: the drawn part is off
  EXPECT_EQ(s.drones[1].clock_drift_ppm, 0.0);

  // An ideal file with single values; the preset from outside.
  const std::string ideal_keys =
      "imperfections: {preset: ideal, lidar: {range_noise_per_m: 0.001}, clock: {drift_sigma_ppm: 3}}\n";
  ScenarioOverrides realistic;
  realistic.imperfections = ImperfectionPreset::kRealistic;
  status = ParseScenario(Scenario2(ideal_keys), "x.yaml", &s, realistic);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(s.imperfections, ImperfectionPreset::kRealistic);
  EXPECT_EQ(s.drones[0].lidar.imperfections.range_noise_per_m, 0.001);
  EXPECT_EQ(s.drones[0].lidar.imperfections.angular_noise_deg, 0.15);
  EXPECT_EQ(Dump(s.drones[0].imu.imperfections), Dump(RealisticImuImperfections()));
  ScenarioOverrides ideal;
  ideal.imperfections = ImperfectionPreset::kIdeal;
  status = ParseScenario(Scenario2("imperfections: realistic\n"), "x.yaml", &s, ideal);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(s.imperfections, ImperfectionPreset::kIdeal);
  EXPECT_EQ(Dump(s.drones[1].lidar.imperfections), Dump(LidarImperfectionOptions()));
  EXPECT_EQ(s.drones[1].clock_drift_ppm, 0.0);
}

TEST(Imperfections, ErrorsNameFileLineAndKey) {
  struct Case {
    std::string yaml;
    std::string lidar0;
    std::string expected;
  };
  const Case cases[] = {
      {"imperfections: bogus\n", "",
       "x.yaml:16: imperfections: unknown value 'bogus' (choices: ideal, realistic)"},
      {"imperfections: {lidar: {angular_noise: 1}}\n", "", "imperfections.lidar.angular_noise"},
      {"imperfections:\n  preset: ideal\n  lidar: {mixed_pixel_probability: 0.5}\n", "",
       "x.yaml:18: imperfections.lidar.mixed_pixel_probability: needs a beam footprint"},
      {"imperfections:\n  calibration: {extrinsic_rotation_deg: [0.5, 0.2]}\n", "",
       "imperfections.calibration.extrinsic_rotation_deg: min must not exceed max"},
      {"imperfections:\n  imu: {timestamp_jitter_s: 1}\n", "",
       "x.yaml:17: imperfections.imu.timestamp_jitter_s: value 1 is out of range"},
      {"imperfections: ideal\n", ", imperfections: {multi_return: true}",
       "drones[0].lidar.imperfections.multi_return: needs a beam footprint"},
  };
  for (const Case& c : cases) {
    Scenario s;
    const Status status = ParseScenario(Scenario2(c.yaml, c.lidar0), "x.yaml", &s);
    ASSERT_FALSE(status.ok()) << c.yaml << c.lidar0;
    EXPECT_NE(status.message().find(c.expected), std::string::npos) << status.message();
  }
  // Over the realistic preset, the same key is fine (it has a footprint).
  Scenario s;
  const Status ok = ParseScenario(
      Scenario2("imperfections: realistic\n", ", imperfections: {multi_return: true}"), "x.yaml",
      &s);
  EXPECT_TRUE(ok.ok()) << ok.message();
}

// The calibration error: magnitudes uniform in their [min, max], directions
// uniform, time error of either sign; applied exactly.
TEST(Imperfections, CalibrationErrorMagnitudesInRange) {
  const CalibrationErrorOptions o = RealisticCalibrationError();
  const int n = 2000;
  double angle_sum = 0.0, length_sum = 0.0, positive = 0.0;
  Eigen::Vector3d axis_sum = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    const CalibrationError e = DrawCalibrationError(o, static_cast<uint64_t>(k));
    const double angle = e.rotation_rad.norm() / kDeg;
    const double length = e.translation_m.norm();
    const double dt = std::abs(e.imu_time_offset_s);
    ASSERT_GE(angle, 0.2);
    ASSERT_LE(angle, 0.5);
    ASSERT_GE(length, 0.005);
    ASSERT_LE(length, 0.010);
    ASSERT_GE(dt, 0.0005);
    ASSERT_LE(dt, 0.0015);
    angle_sum += angle;
    length_sum += length;
    positive += e.imu_time_offset_s > 0.0;
    axis_sum += e.rotation_rad.normalized();
    SensorCalibration truth;
    truth.R_imu_lidar = so3::Exp(Eigen::Vector3d(0.1, -0.2, 0.3));
    truth.p_lidar_in_imu_m = Eigen::Vector3d(0.01, 0.02, 0.03);
    truth.imu_time_offset_s = 0.002;
    const SensorCalibration given = ApplyCalibrationError(truth, e);
    ASSERT_NEAR(AngleDeg(truth.R_imu_lidar, given.R_imu_lidar), angle, 1e-9);
    ASSERT_NEAR((given.p_lidar_in_imu_m - truth.p_lidar_in_imu_m).norm(), length, 1e-15);
    ASSERT_NEAR(given.imu_time_offset_s - truth.imu_time_offset_s, e.imu_time_offset_s, 1e-15);
  }
  // Uniform magnitudes: the means at the middle of the ranges (3 sigma).
  EXPECT_LT(std::abs(angle_sum / n - 0.35), 3.0 * 0.3 / std::sqrt(12.0 * n));
  EXPECT_LT(std::abs(length_sum / n - 0.0075), 3.0 * 0.005 / std::sqrt(12.0 * n));
  EXPECT_LT(std::abs(positive - 0.5 * n), 3.0 * std::sqrt(0.25 * n));
  // Isotropic directions: each component of the mean unit vector ~ N(0, 1/(3n)).
  EXPECT_LT((axis_sum / n).cwiseAbs().maxCoeff(), 4.0 / std::sqrt(3.0 * n));
  // Nothing asked, nothing drawn.
  const CalibrationError none = DrawCalibrationError(CalibrationErrorOptions(), 1);
  EXPECT_TRUE(none.rotation_rad.isZero(0.0));
  EXPECT_TRUE(none.translation_m.isZero(0.0));
  EXPECT_EQ(none.imu_time_offset_s, 0.0);
}

// The truth of the resolved scenario as written (every key of the block).
struct TruthBlock {
  Eigen::Matrix3d R_imu_lidar = Eigen::Matrix3d::Zero();
  Eigen::Vector3d p_lidar_in_imu_m = Eigen::Vector3d::Zero();
  double imu_time_offset_s = -1.0;
  double clock_offset_s = -1.0;
  double clock_drift_ppm = -1.0;
  Eigen::Matrix3d imu_gyro_matrix = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d imu_accel_matrix = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g1 = Eigen::Vector3d::Zero(), g2 = g1, a1 = g1, a2 = g1;
  template <class V>
  void VisitFields(V&& v) {
    v("R_imu_lidar", R_imu_lidar);
    v("p_lidar_in_imu_m", p_lidar_in_imu_m);
    v("imu_time_offset_s", imu_time_offset_s);
    v("clock_offset_s", clock_offset_s);
    v("clock_drift_ppm", clock_drift_ppm);
    v("imu_gyro_matrix", imu_gyro_matrix);
    v("imu_accel_matrix", imu_accel_matrix);
    v("imu_gyro_vibration_phase_rad", g1);
    v("imu_gyro_vibration_harmonic_phase_rad", g2);
    v("imu_accel_vibration_phase_rad", a1);
    v("imu_accel_vibration_harmonic_phase_rad", a2);
  }
  std::string Validate() const { return {}; }
};

struct OdometryBlock {
  double imu_time_offset_s = -1.0;
  template <class V>
  void VisitFields(V&& v) {
    v("imu_time_offset_s", imu_time_offset_s);
  }
  std::string Validate() const { return {}; }
};

// swarm.yaml hands the estimator the calibrated extrinsic and time offset
// (realistic: off the truth by the drawn error); resolved_scenario.yaml keeps
// the truth. With `ideal` the manifest has the truth.
TEST(Imperfections, ManifestHasTheCalibrationResolvedScenarioTheTruth) {
  for (const char* preset : {"ideal", "realistic"}) {
    SCOPED_TRACE(preset);
    const bool realistic = std::string(preset) == "realistic";
    Scenario s;
    const Status status =
        ParseScenario(Scenario2(std::string("imperfections: ") + preset + "\n"), "x.yaml", &s);
    ASSERT_TRUE(status.ok()) << status.message();
    Simulator sim(std::move(s.scene), s.drones, s.objects, s.simulation_config());
    config::ConfigFile manifest, resolved;
    ASSERT_TRUE(
        config::ConfigFile::Parse(ReplayManifestYaml(s, sim), "swarm.yaml", &manifest).ok());
    ASSERT_TRUE(
        config::ConfigFile::Parse(ResolvedScenarioYaml(s, sim), "resolved.yaml", &resolved).ok());
    for (size_t i = 0; i < s.drones.size(); ++i) {
      SCOPED_TRACE(i);
      const DroneConfig& d = s.drones[i];
      const std::string key = config::IndexKey("drones", i);
      LidarOptions given;
      OdometryBlock odometry;
      TruthBlock truth;
      ASSERT_TRUE(manifest.Read(key + ".lidar", &given).ok());
      ASSERT_TRUE(manifest.Read(key + ".odometry", &odometry).ok());
      const Status read_truth = resolved.Read(key + ".truth", &truth);
      ASSERT_TRUE(read_truth.ok()) << read_truth.message();
      // The truth block is the simulated sensor and clock.
      EXPECT_LT((truth.R_imu_lidar - d.lidar.sensor.QuaternionImuLidar().toRotationMatrix()).norm(),
                1e-15);
      EXPECT_EQ(truth.p_lidar_in_imu_m, d.lidar.sensor.p_lidar_in_imu_m);
      EXPECT_EQ(truth.imu_time_offset_s, d.imu.time_offset_s);
      EXPECT_EQ(truth.clock_drift_ppm, d.clock_drift_ppm);
      EXPECT_EQ(truth.imu_gyro_matrix, sim.ImuErrorsOf(static_cast<int>(i)).gyro_matrix);
      // The manifest: the calibration handed to the estimator.
      const double angle =
          AngleDeg(truth.R_imu_lidar, given.QuaternionImuLidar().toRotationMatrix());
      const double length = (given.p_lidar_in_imu_m - truth.p_lidar_in_imu_m).norm();
      const double dt = std::abs(odometry.imu_time_offset_s - truth.imu_time_offset_s);
      if (realistic) {
        EXPECT_GE(angle, 0.2 - 1e-9);
        EXPECT_LE(angle, 0.5 + 1e-9);
        EXPECT_GE(length, 0.005 - 1e-12);
        EXPECT_LE(length, 0.010 + 1e-12);
        EXPECT_GE(dt, 0.0005 - 1e-12);
        EXPECT_LE(dt, 0.0015 + 1e-12);
      } else {
        EXPECT_EQ(given.R_imu_lidar, d.lidar.sensor.R_imu_lidar);
        EXPECT_EQ(given.p_lidar_in_imu_m, d.lidar.sensor.p_lidar_in_imu_m);
        EXPECT_EQ(odometry.imu_time_offset_s, d.imu.time_offset_s);
      }
    }
  }
}

// Records what one drone emits.
class RecordingSink : public DroneSink {
 public:
  Status OnImu(const ImuSample& imu) override {
    imu_stamps.push_back(imu.stamp_ns);
    return Status::Ok();
  }
  Status OnScan(const LidarScan& scan, int64_t) override {
    scan_stamps.push_back(scan.stamp_ns);
    return Status::Ok();
  }
  Status OnGroundTruth(const PoseStamped& pose) override {
    gt_stamps.push_back(pose.stamp_ns);
    return Status::Ok();
  }
  std::vector<int64_t> imu_stamps, scan_stamps, gt_stamps;
};

// Clock drift: N(0, drift_sigma_ppm) per drone (std within 10 % over 2000
// drones); a drone's stamps run at 1 + drift of true time, for every record.
TEST(Imperfections, ClockDriftScalesEveryStamp) {
  ClockImperfectionOptions o;
  o.drift_sigma_ppm = 20.0;
  std::vector<double> drift;
  double mean = 0.0, sq = 0.0;
  for (uint64_t seed = 0; seed < 2000; ++seed) drift.push_back(DrawClockDriftPpm(o, seed));
  for (double d : drift) mean += d / drift.size();
  for (double d : drift) sq += (d - mean) * (d - mean);
  EXPECT_NEAR(std::sqrt(sq / (drift.size() - 1)) / 20.0, 1.0, 0.1);
  EXPECT_LT(std::abs(mean), 4.0 * 20.0 / std::sqrt(2000.0));

  Scenario s;
  ASSERT_TRUE(
      ParseScenario(Scenario2("imperfections: ideal\n", "",
                              "\n    clock_drift_ppm: 500\n    clock_offset_s: 0.25"),
                    "x.yaml", &s)
          .ok());
  Simulator sim(std::move(s.scene), s.drones, s.objects, s.simulation_config());
  const double origin_ns = 1000e9 + 0.25e9;
  for (double t : {0.0, 0.5, 1.0}) {
    EXPECT_NEAR(static_cast<double>(sim.StampNs(0, t)), origin_ns + t * (1.0 + 500e-6) * 1e9, 1.0);
    EXPECT_EQ(sim.StampNs(1, t), std::llround((1000.0 + t) * 1e9));  // no drift
  }
  RecordingSink sinks[2];
  std::vector<DroneStats> stats;
  ASSERT_TRUE(sim.Run({&sinks[0], &sinks[1]}, &stats).ok());
  // 1 s of true time spans 1 s + 500 us of drone 0's clock (IMU at 200 Hz).
  const std::vector<int64_t>& imu = sinks[0].imu_stamps;
  ASSERT_EQ(imu.size(), 200u);
  EXPECT_NEAR(static_cast<double>(imu.back() - imu.front()), 199 * 5e6 * (1.0 + 500e-6), 1.0);
  EXPECT_NEAR(static_cast<double>(sinks[0].gt_stamps.back() - sinks[0].gt_stamps.front()),
              99 * 1e7 * (1.0 + 500e-6), 1.0);
  EXPECT_EQ(sinks[1].imu_stamps.back() - sinks[1].imu_stamps.front(), 199 * 5000000LL);
}

// A realistic run: IMU samples are lost at their rate and jittered, stamps
// still increase; two runs give the same records.
TEST(Imperfections, RealisticRunLosesAndJittersImuSamples) {
  const std::string keys =
      "imperfections: {preset: realistic, imu: {sample_dropout_probability: 0.1}}\n";
  std::vector<int64_t> reference;
  for (int run = 0; run < 2; ++run) {
    Scenario s;
    ASSERT_TRUE(ParseScenario(Scenario2(keys), "x.yaml", &s).ok());
    SimulationConfig config = s.simulation_config();
    config.duration_s = 5.0;
    config.num_threads = run + 1;
    Simulator sim(std::move(s.scene), s.drones, s.objects, config);
    RecordingSink sinks[2];
    std::vector<DroneStats> stats;
    ASSERT_TRUE(sim.Run({&sinks[0], &sinks[1]}, &stats).ok());
    const std::vector<int64_t>& imu = sinks[1].imu_stamps;
    const double n = 1000.0;  // 5 s at 200 Hz
    EXPECT_LT(std::abs(imu.size() - 0.9 * n), 3.0 * std::sqrt(n * 0.1 * 0.9));
    int off_grid = 0;
    for (size_t k = 1; k < imu.size(); ++k) {
      ASSERT_GT(imu[k], imu[k - 1]);
      off_grid += (imu[k] - imu[0]) % 5000000 != 0;
    }
    EXPECT_GT(off_grid, static_cast<int>(imu.size()) / 2);  // jitter and drift
    if (run == 0) reference = imu;
    EXPECT_EQ(imu, reference);
  }
}

}  // namespace
}  // namespace swarmlio::sim
