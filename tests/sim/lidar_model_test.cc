#include "swarmlio/sim/lidar_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "swarmlio/config/sensor_preset.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Room: inner faces at x = +-10, y = +-8, z = 0 and 4, with a pillar of radius
// 0.5 at (3, 2). Walls are 0.5 m thick boxes.
void BuildRoom(Scene* scene) {
  const Material wall = Material::Diffuse(60.0);
  AddRoom(Eigen::Vector3d::Zero(), Eigen::Vector3d(20, 16, 4), 0.5, wall, /*ceiling=*/true, scene);
  scene->Add(Primitive::VerticalCylinder({3, 2, 0}, 0.5, 4.0, Material::Diffuse(30.0)));
  scene->Build();
}

double DistanceToRoomSurface(const Eigen::Vector3d& p) {
  double d = std::min({std::abs(p.x() - 10), std::abs(p.x() + 10), std::abs(p.y() - 8),
                       std::abs(p.y() + 8), std::abs(p.z()), std::abs(p.z() - 4)});
  const double r = (p.head<2>() - Eigen::Vector2d(3, 2)).norm();
  d = std::min(d, std::abs(r - 0.5));
  if (r <= 0.5 + 1e-9) d = std::min(d, std::min(std::abs(p.z()), std::abs(p.z() - 4)));
  return d;
}

Trajectory FastFlight(const Eigen::Vector3d& start, uint64_t seed, double speed = 3.0) {
  TrajectoryBuilderOptions opt;
  opt.max_speed_m_s = speed;
  opt.max_yaw_rate_rad_s = 2.0;
  TrajectoryBuilder b(start, 0.0, opt, seed);
  b.Hover(0.5);
  b.Excite(12.0, Eigen::Vector3d(2.0, 2.0, 0.6), 1.5, 1.0);
  return b.Build(0.0, 20.0);
}

// The LiDAR of a sensor preset in configs/ (simulation extras at defaults).
SimulatedLidarOptions Preset(const std::string& file) {
  SimulatedLidarOptions o;
  const Status status =
      config::LoadSensorPreset(std::string(SWARMLIO_SOURCE_DIR) + "/configs/" + file, &o.sensor, nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  return o;
}

SimulatedLidarOptions NoiseFree(SimulatedLidarOptions o) {
  o.sensor.range_noise_stddev_m = 0.0;
  o.dropout_probability = 0.0;
  o.sensor.R_imu_lidar = (Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d::UnitZ()) *
                          Eigen::AngleAxisd(-20.0 * kDeg, Eigen::Vector3d::UnitY()) *
                          Eigen::AngleAxisd(2.0 * kDeg, Eigen::Vector3d::UnitX()))
                             .toRotationMatrix();
  return o;
}

Eigen::Vector3d WorldPoint(const Trajectory& traj, const SimulatedLidarOptions& o,
                           const SimulatedPoint& p) {
  const Pose T_W_b = traj.PoseAt(p.t_s);
  const Eigen::Matrix3d R_imu_lidar = o.sensor.QuaternionImuLidar().toRotationMatrix();
  return T_W_b.R_W_b * (R_imu_lidar * p.p_in_lidar + o.sensor.p_lidar_in_imu_m) + T_W_b.p_b_in_W;
}

// Parameter: the preset file of a LiDAR type.
class LidarTypes : public ::testing::TestWithParam<const char*> {};

TEST_P(LidarTypes, NoiseFreePointsLieOnSurfacesWithEgoMotion) {
  Scene scene;
  BuildRoom(&scene);
  const Trajectory traj = FastFlight(Eigen::Vector3d(-2, -1, 1.5), 3);
  const SimulatedLidarOptions o = NoiseFree(Preset(GetParam()));
  LidarModel lidar(o, &traj, &scene, nullptr, -1, 1);
  SimulatedScan scan;
  double max_err = 0.0;
  double max_err_frame_start_pose = 0.0;
  for (int64_t frame : {5, 37}) {
    lidar.Scan(frame, &scan);
    ASSERT_GT(scan.points.size(), 0.9 * scan.num_pulses);  // closed room: nearly all return
    for (const SimulatedPoint& p : scan.points) {
      max_err = std::max(max_err, DistanceToRoomSurface(WorldPoint(traj, o, p)));
      SimulatedPoint at_start = p;
      at_start.t_s = scan.start_time_s;
      max_err_frame_start_pose =
          std::max(max_err_frame_start_pose, DistanceToRoomSurface(WorldPoint(traj, o, at_start)));
    }
  }
  EXPECT_LT(max_err, 1e-6);
  EXPECT_GT(max_err_frame_start_pose, 1e-2);  // ego motion within the frame matters
}

TEST_P(LidarTypes, StampsIncreaseAndSpanTheFrame) {
  Scene scene;
  BuildRoom(&scene);
  const Trajectory traj = FastFlight(Eigen::Vector3d(0, 0, 1.5), 4);
  SimulatedLidarOptions o = Preset(GetParam());
  o.start_time_s = 0.25;
  LidarModel lidar(o, &traj, &scene, nullptr, -1, 2);
  SimulatedScan scan;
  for (int64_t frame = 0; frame < 3; ++frame) {
    lidar.Scan(frame, &scan);
    EXPECT_NEAR(scan.start_time_s, 0.25 + frame * 0.1, 1e-12);
    ASSERT_GT(scan.points.size(), 1000u);
    for (size_t i = 1; i < scan.points.size(); ++i) {
      ASSERT_GT(scan.points[i].t_s, scan.points[i - 1].t_s);
    }
    EXPECT_GE(scan.points.front().t_s, scan.start_time_s);
    EXPECT_LT(scan.points.front().t_s - scan.start_time_s, 1e-3);
    EXPECT_LT(scan.points.back().t_s, scan.start_time_s + scan.period_s);
    EXPECT_GT(scan.points.back().t_s, scan.start_time_s + scan.period_s - 1e-3);
  }
  const double expected_pulses = o.sensor.points_per_second / o.sensor.scan_rate_hz;
  EXPECT_NEAR(static_cast<double>(scan.num_pulses), expected_pulses, 1.0);
  // Noise: the range noise (2-3 cm) shows up as distance to the surfaces.
  double sum_sq = 0.0;
  for (const SimulatedPoint& p : scan.points) {
    const double e = DistanceToRoomSurface(WorldPoint(traj, o, p));
    sum_sq += e * e;
  }
  const double rms = std::sqrt(sum_sq / scan.points.size());
  EXPECT_GT(rms, 0.25 * o.sensor.range_noise_stddev_m);
  EXPECT_LT(rms, 1.5 * o.sensor.range_noise_stddev_m);
}

INSTANTIATE_TEST_SUITE_P(AllTypes, LidarTypes,
                         ::testing::Values("livox_avia.yaml", "livox_mid360.yaml",
                                           "spinning_32.yaml"));

TEST(LidarPattern, FieldsOfView) {
  {
    const LidarPattern avia(Preset("livox_avia.yaml").sensor);
    double max_az = 0, max_el = 0;
    int center = 0;
    for (int64_t k = 0; k < 240000; k += 7) {
      Eigen::Vector3d d;
      uint8_t line;
      avia.Direction(k, &d, &line);
      EXPECT_LT(line, 6);
      const double az = std::atan2(d.y(), d.x());
      const double el = std::asin(d.z());
      max_az = std::max(max_az, std::abs(az));
      max_el = std::max(max_el, std::abs(el));
      if (std::abs(az) < 3 * kDeg && std::abs(el) < 3 * kDeg) ++center;
    }
    EXPECT_NEAR(max_az, 35.2 * kDeg, 1.5 * kDeg);
    EXPECT_NEAR(max_el, 38.6 * kDeg, 1.5 * kDeg);
    EXPECT_GT(center, 50);  // the rosette passes through the centre
  }
  {
    const LidarPattern mid(Preset("livox_mid360.yaml").sensor);
    double min_el = 1, max_el = -1;
    for (int64_t k = 0; k < 200000; k += 3) {
      Eigen::Vector3d d;
      uint8_t line;
      mid.Direction(k, &d, &line);
      min_el = std::min(min_el, std::asin(d.z()));
      max_el = std::max(max_el, std::asin(d.z()));
    }
    EXPECT_NEAR(min_el, -7 * kDeg, 0.2 * kDeg);
    EXPECT_NEAR(max_el, 52 * kDeg, 0.2 * kDeg);
  }
  {
    // Rings evenly over the preset's vertical FoV, columns over 360 deg.
    const LidarOptions sensor = Preset("spinning_32.yaml").sensor;
    const LidarPattern spinning(sensor);
    EXPECT_EQ(spinning.lines(), 32);
    double min_el = 1, max_el = -1, min_az = 10, max_az = -10;
    for (int64_t k = 0; k < spinning.pulses_per_frame(); ++k) {
      Eigen::Vector3d d;
      uint8_t line;
      spinning.Direction(k, &d, &line);
      ASSERT_EQ(line, k % 32);
      min_el = std::min(min_el, std::asin(d.z()));
      max_el = std::max(max_el, std::asin(d.z()));
      min_az = std::min(min_az, std::atan2(d.y(), d.x()));
      max_az = std::max(max_az, std::atan2(d.y(), d.x()));
    }
    EXPECT_NEAR(min_el, sensor.fov_vertical_min_deg * kDeg, 1e-9);
    EXPECT_NEAR(max_el, sensor.fov_vertical_max_deg * kDeg, 1e-9);
    EXPECT_NEAR(min_az, -M_PI, 0.01);
    EXPECT_NEAR(max_az, M_PI, 0.01);
  }
  // Non-repetitive: frame 0 and frame 1 differ.
  const LidarPattern avia(Preset("livox_avia.yaml").sensor);
  Eigen::Vector3d d0, d1;
  uint8_t line;
  avia.Direction(100, &d0, &line);
  avia.Direction(100 + 24000, &d1, &line);
  EXPECT_GT((d0 - d1).norm(), 1e-3);
}

// Two drones: the observer flies (ego motion), the target flies fast nearby.
struct TwoDrones {
  Scene scene;
  std::unique_ptr<Trajectory> observer, target;
  std::vector<MovingObject> objects;
  TwoDrones(double target_speed, const Eigen::Vector3d& target_start) {
    BuildRoom(&scene);
    TrajectoryBuilderOptions slow;
    slow.max_speed_m_s = 0.5;
    TrajectoryBuilder b(Eigen::Vector3d(-6, 0, 1.5), 0.0, slow, 9);
    b.Hover(0.2);
    b.Excite(15.0, Eigen::Vector3d(0.3, 0.3, 0.1), 0.1, 2.0);
    observer = std::make_unique<Trajectory>(b.Build(0.0, 20.0));
    TrajectoryBuilderOptions fast;
    fast.max_speed_m_s = target_speed;
    TrajectoryBuilder c(target_start, 0.0, fast, 10);
    c.Hover(0.2);
    c.Excite(15.0, Eigen::Vector3d(1.0, 1.5, 0.5), 1.0, 1.0);
    target = std::make_unique<Trajectory>(c.Build(0.0, 20.0));
    for (const Trajectory* t : {observer.get(), target.get()}) {
      MovingObject obj;
      obj.trajectory = t;
      obj.parts_b = MakeDroneBody(DroneBodyOptions());
      obj.Finalize();
      objects.push_back(obj);
    }
  }
};

// Signed distance of a body-frame point to the box part (0 on its surface).
double BoxDistance(const Primitive& part, const Eigen::Vector3d& q_b) {
  const Eigen::Vector3d q = part.rotation().transpose() * (q_b - part.center());
  return (q.cwiseAbs() - part.half_extents()).maxCoeff();
}

TEST(LidarModel, MovingTeammatePointsTakenAtTheirOwnTime) {
  TwoDrones world(4.0, Eigen::Vector3d(-3, 0, 1.5));
  SimulatedLidarOptions o = NoiseFree(Preset("livox_avia.yaml"));
  o.sensor.points_per_second = 60000;  // fewer rays: keeps the test fast under sanitizers
  LidarModel lidar(o, world.observer.get(), &world.scene, &world.objects, 0, 3);
  SimulatedScan scan;
  int on_target = 0;
  double max_err = 0.0, max_err_frame_start = 0.0;
  for (int64_t frame = 10; frame < 70; ++frame) {
    lidar.Scan(frame, &scan);
    for (const SimulatedPoint& p : scan.points) {
      EXPECT_NE(p.object, 0);  // never sees itself
      const Eigen::Vector3d p_W = WorldPoint(*world.observer, o, p);
      if (p.object != 1) {
        max_err = std::max(max_err, DistanceToRoomSurface(p_W));
        continue;
      }
      ++on_target;
      for (bool own_time : {true, false}) {
        const Pose T_W_t = world.target->PoseAt(own_time ? p.t_s : scan.start_time_s);
        const Eigen::Vector3d q_b = T_W_t.R_W_b.transpose() * (p_W - T_W_t.p_b_in_W);
        double d = 1e9;
        for (const Primitive& part : world.objects[1].parts_b) {
          d = std::min(d, std::abs(BoxDistance(part, q_b)));
        }
        (own_time ? max_err : max_err_frame_start) =
            std::max(own_time ? max_err : max_err_frame_start, d);
      }
    }
  }
  EXPECT_GT(on_target, 100);
  EXPECT_LT(max_err, 1e-6);
  EXPECT_GT(max_err_frame_start, 0.01);
}

TEST(LidarModel, TapeSeenWithHighButNotAlwaysDetectableReflectivity) {
  for (double distance : {3.0, 8.0, 14.0}) {
    TwoDrones world(0.8, Eigen::Vector3d(-6 + distance, 0, 1.5));
    const SimulatedLidarOptions o = Preset("livox_avia.yaml");
    LidarModel lidar(o, world.observer.get(), &world.scene, &world.objects, 0, 4);
    SimulatedScan scan;
    int tape = 0, above_200 = 0, above_240 = 0, diffuse_max = 0;
    for (int64_t frame = 10; frame < 40; ++frame) {
      lidar.Scan(frame, &scan);
      for (const SimulatedPoint& p : scan.points) {
        if (p.object == 1 && p.primitive == 1) {
          ++tape;
          EXPECT_GE(p.reflectivity, 151);
          above_200 += p.reflectivity > 200;
          above_240 += p.reflectivity > 240;
        } else {
          diffuse_max = std::max(diffuse_max, static_cast<int>(p.reflectivity));
        }
      }
    }
    EXPECT_GT(tape, 2) << distance;
    EXPECT_LE(diffuse_max, 150);
    EXPECT_GT(above_200, tape / 3) << distance;  // detectable...
    EXPECT_LT(above_240, tape) << distance;      // ...but not always above a 240 threshold
  }
}

}  // namespace
}  // namespace swarmlio::sim
