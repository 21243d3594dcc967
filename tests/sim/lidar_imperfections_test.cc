// Statistical tests of the LiDAR imperfections (LidarImperfectionOptions):
// each effect is measured on seeded scans of a static sensor in a known room
// and compared with its setting (std within 10 %, rates within 3 sigma of the
// binomial, biases within 4 standard errors).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "swarmlio/config/sensor_preset.h"
#include "swarmlio/sim/lidar_model.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A hovering IMU at `p` (yaw 0: body = world axes), LiDAR at the IMU.
Trajectory Hovering(const Eigen::Vector3d& p) {
  TrajectoryBuilder b(p, 0.0, TrajectoryBuilderOptions(), 1);
  b.Hover(10.0);
  return b.Build(0.0, 10.0);
}

// Walls only: inner faces x = +-10, y = +-8, z = 0 and 4 (normal known per face).
void BuildEmptyRoom(double albedo_percent, Scene* scene) {
  AddRoom(Eigen::Vector3d::Zero(), Eigen::Vector3d(20, 16, 4), 0.5,
          Material::Diffuse(albedo_percent), /*ceiling=*/true, scene);
}

// Normal of the room face a world point lies on.
Eigen::Vector3d RoomNormal(const Eigen::Vector3d& p) {
  const double dx = 10.0 - std::abs(p.x()), dy = 8.0 - std::abs(p.y());
  const double dz = std::min(std::abs(p.z()), std::abs(4.0 - p.z()));
  if (dx <= dy && dx <= dz) return Eigen::Vector3d::UnitX();
  if (dy <= dz) return Eigen::Vector3d::UnitY();
  return Eigen::Vector3d::UnitZ();
}

// Range along the unit direction `d` from `o` to the room's walls.
double RoomRange(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t = 1e9;
  const Eigen::Vector3d lo(-10, -8, 0), hi(10, 8, 4);
  for (int i = 0; i < 3; ++i) {
    if (d[i] > 1e-12) t = std::min(t, (hi[i] - o[i]) / d[i]);
    if (d[i] < -1e-12) t = std::min(t, (lo[i] - o[i]) / d[i]);
  }
  return t;
}

// A preset's LiDAR with every noise and loss off (identity extrinsic).
SimulatedLidarOptions Clean(const std::string& preset) {
  SimulatedLidarOptions o;
  const Status status = config::LoadSensorPreset(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/" + preset, &o.sensor, nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  o.sensor.range_noise_stddev_m = 0.0;
  o.sensor.R_imu_lidar = Eigen::Matrix3d::Identity();
  o.sensor.p_lidar_in_imu_m = Eigen::Vector3d::Zero();
  o.dropout_probability = 0.0;
  return o;
}

std::vector<SimulatedPoint> ScanFrames(const SimulatedLidarOptions& o,
                                       const Trajectory& traj,
                                       const Scene& scene,
                                       int frames,
                                       uint64_t seed = 7) {
  LidarModel lidar(o, &traj, &scene, nullptr, -1, seed);
  std::vector<SimulatedPoint> points;
  SimulatedScan scan;
  for (int f = 0; f < frames; ++f) {
    lidar.Scan(f, &scan);
    points.insert(points.end(), scan.points.begin(), scan.points.end());
  }
  return points;
}

// Unit vectors normal to the beam as the model defines them (h horizontal).
void Axes(const Eigen::Vector3d& d, Eigen::Vector3d* h, Eigen::Vector3d* v) {
  *h = Eigen::Vector3d::UnitZ().cross(d).normalized();
  *v = d.cross(*h);
}

double Std(const std::vector<double>& x) {
  double mean = 0.0, sq = 0.0;
  for (double v : x) mean += v;
  mean /= x.size();
  for (double v : x) sq += (v - mean) * (v - mean);
  return std::sqrt(sq / (x.size() - 1));
}

double Mean(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v;
  return s / x.size();
}

// Beam direction error: per-axis std within 10 % of angular_noise_deg; points
// are reported along the nominal direction.
TEST(LidarImperfections, AngularNoiseStdMatchesSetting) {
  Scene scene;
  BuildEmptyRoom(60.0, &scene);
  scene.Build();
  const Trajectory traj = Hovering(Eigen::Vector3d(0.5, -0.3, 1.5));
  for (const char* preset : {"livox_mid360.yaml", "livox_avia.yaml"}) {
    SimulatedLidarOptions o = Clean(preset);
    o.imperfections.angular_noise_deg = 0.15;
    const std::vector<SimulatedPoint> points = ScanFrames(o, traj, scene, 2);
    ASSERT_GT(points.size(), 20000u);
    std::vector<double> err_h, err_v;
    double sum_sq = 0.0;
    for (const SimulatedPoint& p : points) {
      const Eigen::Vector3d nominal = p.p_in_lidar.normalized();
      const Eigen::Vector3d actual = p.true_p_in_lidar.normalized();
      Eigen::Vector3d h, v;
      Axes(nominal, &h, &v);
      err_h.push_back((actual - nominal).dot(h));
      err_v.push_back((actual - nominal).dot(v));
      sum_sq += std::pow(std::acos(std::clamp(nominal.dot(actual), -1.0, 1.0)), 2);
      // The measured range is the range of the surface the beam really hit.
      ASSERT_NEAR(p.p_in_lidar.norm(), p.true_range_m, 1e-9);
    }
    const double sigma = 0.15 * kDeg;
    EXPECT_NEAR(Std(err_h) / sigma, 1.0, 0.1) << preset;
    EXPECT_NEAR(Std(err_v) / sigma, 1.0, 0.1) << preset;
    EXPECT_NEAR(std::sqrt(sum_sq / (2.0 * points.size())) / sigma, 1.0, 0.1) << preset;
    EXPECT_LT(std::abs(Mean(err_h)), 4.0 * sigma / std::sqrt(points.size())) << preset;
  }
  // Off: exactly the nominal direction.
  const std::vector<SimulatedPoint> ideal = ScanFrames(Clean("livox_mid360.yaml"), traj, scene, 1);
  for (const SimulatedPoint& p : ideal) {
    ASSERT_LT((p.p_in_lidar - p.true_p_in_lidar).norm(), 1e-9);
  }
}

// Range noise: sigma^2 = s0^2 + (k r)^2 + (r div tan(inc) / 4)^2. The error
// normalised by that prediction has std 1 (within 10 %) at short and long
// range and at small and large incidence; the raw std grows.
TEST(LidarImperfections, RangeNoiseGrowsWithRangeAndIncidence) {
  Scene scene;
  BuildEmptyRoom(60.0, &scene);
  scene.Build();
  const Eigen::Vector3d origin(-2.0, -1.0, 1.0);  // walls 7-12 m away, ceiling 3 m
  const Trajectory traj = Hovering(origin);
  SimulatedLidarOptions o = Clean("livox_mid360.yaml");
  o.sensor.range_noise_stddev_m = 0.01;
  o.imperfections.range_noise_per_m = 0.004;
  o.imperfections.incidence_noise = true;
  o.imperfections.beam_divergence_horizontal_deg = 0.6;
  o.imperfections.beam_divergence_vertical_deg = 0.4;
  const double div = std::sqrt(0.5 * (0.6 * 0.6 + 0.4 * 0.4)) * kDeg;
  const double min_cos = std::cos(85.0 * kDeg);
  const std::vector<SimulatedPoint> points = ScanFrames(o, traj, scene, 4);
  ASSERT_GT(points.size(), 50000u);
  // Bins: mid (6-10 m) / far (> 10 m), head-on (cos > 0.8) / slanted (cos < 0.4).
  std::map<std::string, std::vector<double>> z, raw;
  for (const SimulatedPoint& p : points) {
    const Eigen::Vector3d d = p.true_p_in_lidar.normalized();  // world = LiDAR axes here
    const double cos_inc = std::abs(d.dot(RoomNormal(origin + p.true_p_in_lidar)));
    ASSERT_NEAR(cos_inc, p.cos_incidence, 1e-9);
    const double r = p.true_range_m;
    const double c = std::max(cos_inc, min_cos);
    const double spread = r * div * std::sqrt(1 - c * c) / c / 4.0;
    const double sigma = std::sqrt(0.01 * 0.01 + std::pow(0.004 * r, 2) + spread * spread);
    const double e = p.p_in_lidar.norm() - r;
    std::vector<std::string> bins = {"all"};
    const bool mid = r > 6.0 && r < 10.0;
    if (mid && cos_inc > 0.8) bins.push_back("mid_head_on");
    if (r > 10.0 && cos_inc > 0.8) bins.push_back("far_head_on");
    if (mid && cos_inc < 0.4) bins.push_back("mid_slanted");
    for (const std::string& b : bins) {
      z[b].push_back(e / sigma);
      raw[b].push_back(e);
    }
  }
  for (const auto& [bin, values] : z) {
    SCOPED_TRACE(bin);
    ASSERT_GT(values.size(), 500u);
    EXPECT_NEAR(Std(values), 1.0, 0.1);
    EXPECT_LT(std::abs(Mean(values)), 4.0 / std::sqrt(values.size()));
  }
  ASSERT_EQ(z.size(), 4u);
  EXPECT_GT(Std(raw["far_head_on"]), 1.25 * Std(raw["mid_head_on"]));  // grows with range
  EXPECT_GT(Std(raw["mid_slanted"]), 1.25 * Std(raw["mid_head_on"]));  // and with incidence
}

// Range walk: bias = b * max(0, 1 - reflectivity / threshold), so dark
// returns are long and bright ones unbiased.
TEST(LidarImperfections, LowReflectivitySurfacesAreMeasuredLong) {
  const Eigen::Vector3d origin(0.0, 0.0, 1.5);
  const Trajectory traj = Hovering(origin);
  SimulatedLidarOptions o = Clean("livox_mid360.yaml");
  o.sensor.range_noise_stddev_m = 0.01;
  o.imperfections.low_reflectivity_bias_m = 0.05;
  o.imperfections.low_reflectivity_threshold = 20.0;
  for (double albedo : {3.0, 80.0}) {
    SCOPED_TRACE(albedo);
    Scene scene;
    BuildEmptyRoom(albedo, &scene);
    scene.Build();
    const std::vector<SimulatedPoint> points = ScanFrames(o, traj, scene, 2);
    std::vector<double> residual, dark, bright;
    for (const SimulatedPoint& p : points) {
      const double e = p.p_in_lidar.norm() - p.true_range_m;
      const double bias = 0.05 * std::max(0.0, 1.0 - p.reflectivity / 20.0);
      residual.push_back(e - bias);
      if (p.reflectivity <= 4.0) dark.push_back(e);
      if (p.reflectivity >= 20.0) bright.push_back(e);
    }
    EXPECT_LT(std::abs(Mean(residual)), 4.0 * 0.01 / std::sqrt(residual.size()));
    EXPECT_NEAR(Std(residual), 0.01, 0.001);
    if (albedo < 10.0) {
      ASSERT_GT(dark.size(), 1000u);
      EXPECT_GT(Mean(dark), 0.7 * 0.05);  // bias >= 0.05 * (1 - 4/20)
    } else {
      ASSERT_GT(bright.size(), 1000u);
      EXPECT_LT(std::abs(Mean(bright)), 4.0 * 0.01 / std::sqrt(bright.size()));
    }
  }
}

// A plate 4 m in front of the sensor, the room wall behind it.
struct EdgeScene {
  Scene scene;
  Trajectory traj = Hovering(Eigen::Vector3d(0.0, 0.0, 1.5));
  EdgeScene() {
    BuildEmptyRoom(60.0, &scene);
    scene.Add(Primitive::AxisAlignedBox({4.0, -1.0, 0.8}, {4.2, 1.0, 2.2}, Material::Diffuse(50)));
    scene.Build();
  }
  SimulatedLidarOptions Options() const {
    SimulatedLidarOptions o = Clean("livox_avia.yaml");
    o.imperfections.beam_divergence_horizontal_deg = 1.0;
    o.imperfections.beam_divergence_vertical_deg = 1.0;
    return o;
  }
};

// Mixed pixels: only where the footprint straddles a depth edge (most at the
// plate's silhouette), always between the two surfaces at a uniform position;
// their number with probability p is Binomial(number with p = 1, p) (the
// same straddling pulses).
TEST(LidarImperfections, MixedPixelsBetweenSurfacesAtTheGivenRate) {
  const EdgeScene world;
  const Eigen::Vector3d origin(0.0, 0.0, 1.5);
  std::map<double, size_t> counts;
  std::map<double, std::vector<double>> mixed_times;
  std::vector<double> position;  // (r - r_main) / (r_other - r_main) at p = 1
  size_t at_plate_edge = 0;
  for (double p_mix : {0.0, 0.3, 1.0}) {
    SimulatedLidarOptions o = world.Options();
    o.imperfections.mixed_pixel_probability = p_mix;
    const std::vector<SimulatedPoint> points = ScanFrames(o, world.traj, world.scene, 3);
    for (const SimulatedPoint& p : points) {
      const double r = p.p_in_lidar.norm();
      if (!p.mixed) {
        ASSERT_NEAR(r, p.true_range_m, 1e-9);
        continue;
      }
      ASSERT_GT(std::abs(p.mixed_other_range_m - p.true_range_m), 0.1);
      const double w = (r - p.true_range_m) / (p.mixed_other_range_m - p.true_range_m);
      ASSERT_GE(w, 0.0);
      ASSERT_LE(w, 1.0);
      if (p_mix == 1.0) {
        position.push_back(w);
        // One surface is the plate's front (x = 4), the other the wall behind.
        const Eigen::Vector3d d = p.p_in_lidar.normalized();
        const double plate = 4.0 / d.x(), wall = RoomRange(origin, d);
        const double near = std::min(p.true_range_m, p.mixed_other_range_m);
        const double far = std::max(p.true_range_m, p.mixed_other_range_m);
        at_plate_edge += std::abs(near - plate) < 0.1 && std::abs(far - wall) < 0.2;
      }
      mixed_times[p_mix].push_back(p.t_s);
    }
    counts[p_mix] = mixed_times[p_mix].size();
  }
  EXPECT_EQ(counts[0.0], 0u);
  const double n = static_cast<double>(counts[1.0]);
  ASSERT_GT(n, 300.0);
  EXPECT_GT(at_plate_edge, n / 2);
  EXPECT_LT(std::abs(counts[0.3] - 0.3 * n), 3.0 * std::sqrt(n * 0.3 * 0.7));
  EXPECT_LT(std::abs(Mean(position) - 0.5), 3.0 * std::sqrt(1.0 / 12.0 / n));
  // The mixed pulses at p = 0.3 are among those at p = 1.
  for (double t : mixed_times[0.3]) {
    ASSERT_TRUE(std::binary_search(mixed_times[1.0].begin(), mixed_times[1.0].end(), t));
  }
}

// Dual return: every straddling footprint gives a first (tag 0x10) and a
// second (0x20) return at the same time, the nearer first, no mixed pixels.
TEST(LidarImperfections, MultiReturnTagsBothSurfaces) {
  const EdgeScene world;
  SimulatedLidarOptions o = world.Options();
  o.imperfections.mixed_pixel_probability = 1.0;
  const size_t straddling = [&] {
    size_t n = 0;
    for (const SimulatedPoint& p : ScanFrames(o, world.traj, world.scene, 3)) n += p.mixed;
    return n;
  }();
  o.imperfections.mixed_pixel_probability = 0.0;
  o.imperfections.multi_return = true;
  const std::vector<SimulatedPoint> points = ScanFrames(o, world.traj, world.scene, 3);
  size_t second = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const SimulatedPoint& p = points[i];
    EXPECT_FALSE(p.mixed);
    ASSERT_TRUE(p.tag == 0x10 || p.tag == 0x20) << int(p.tag);
    if (p.tag != 0x20) continue;
    ++second;
    ASSERT_GT(i, 0u);
    const SimulatedPoint& first = points[i - 1];
    EXPECT_EQ(first.tag, 0x10);
    EXPECT_EQ(first.t_s, p.t_s);
    EXPECT_GT(p.p_in_lidar.norm(), first.p_in_lidar.norm() + 0.1);
    EXPECT_NEAR((p.p_in_lidar.normalized() - first.p_in_lidar.normalized()).norm(), 0.0, 1e-12);
  }
  // The same footprint samples as the mixed pixels with p = 1.
  EXPECT_EQ(second, straddling);
  EXPECT_GT(second, 300u);
}

// Losses: random dropouts at dropout_probability and range-dependent ones at
// p(r) = p_max (r / max_range)^exponent, each within 3 sigma of its binomial.
TEST(LidarImperfections, DropoutRatesMatchTheirProbabilities) {
  Scene scene;
  BuildEmptyRoom(60.0, &scene);
  scene.Build();
  const Trajectory traj = Hovering(Eigen::Vector3d(-7.0, -5.0, 1.0));
  SimulatedLidarOptions o = Clean("livox_mid360.yaml");
  o.sensor.max_range_m = 15.0;
  const std::vector<SimulatedPoint> all = ScanFrames(o, traj, scene, 3);
  ASSERT_GT(all.size(), 30000u);
  std::map<double, double> range_at_time;
  for (const SimulatedPoint& p : all) range_at_time[p.t_s] = p.true_range_m;

  SimulatedLidarOptions random = o;
  random.dropout_probability = 0.2;
  const double kept_random = ScanFrames(random, traj, scene, 3).size();
  const double n = all.size();
  EXPECT_LT(std::abs(kept_random - 0.8 * n), 3.0 * std::sqrt(n * 0.2 * 0.8));

  SimulatedLidarOptions ranged = o;
  ranged.imperfections.range_dropout_at_max_range = 0.8;
  ranged.imperfections.range_dropout_exponent = 2.0;
  const std::vector<SimulatedPoint> kept = ScanFrames(ranged, traj, scene, 3);
  double expected = 0.0, variance = 0.0, lost_far = 0.0, far = 0.0;
  for (const SimulatedPoint& p : all) {
    const double loss = 0.8 * std::pow(p.true_range_m / 15.0, 2);
    expected += 1.0 - loss;
    variance += loss * (1.0 - loss);
    far += p.true_range_m > 10.0;
  }
  EXPECT_LT(std::abs(kept.size() - expected), 3.0 * std::sqrt(variance));
  for (const SimulatedPoint& p : kept) {
    ASSERT_EQ(range_at_time.count(p.t_s), 1u);  // a subset of the returns
    lost_far -= p.true_range_m > 10.0;
  }
  lost_far += far;
  EXPECT_GT(lost_far / far, 0.8 * std::pow(10.0 / 15.0, 2));  // far returns are lost more
}

}  // namespace
}  // namespace swarmlio::sim
