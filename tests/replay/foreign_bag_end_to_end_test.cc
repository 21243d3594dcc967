// Bags recorded elsewhere, end to end through replay::SwarmReplay: a short
// simulated indoor_3uav flight is rewritten the ways foreign logs differ
// (accelerometer sign flipped by the driver, PointCloud2 without per-point
// time, other topic names with ground truth in another frame) and each must
// track about as well as the original (position RMSE within 2x). No manifest
// topics are set: the reader finds them by type. The same flight simulated
// into an MCAP file (ROS 2 messages) must give the very same trajectory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/config/sensor_preset.h"
#include "swarmlio/eval/consistency.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/io/bag_writer.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/replay/swarm_replay.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"
#include "test_utils/given_calibration.h"

namespace swarmlio::replay {
namespace {

namespace fs = std::filesystem;

constexpr double kDurationS = 8.0;  // 4 s static start, take-off, excitation

// The simulated drone (uav1 of indoor_3uav) and the calibration the
// simulator reports as given (with its error, as swarm.yaml hands it over).
struct SimDrone {
  std::string bag;
  LidarOptions lidar;
  ImuOptions imu;
  double imu_time_offset_s = 0.0;
};

Status Simulate(const fs::path& dir,
                const std::string& name,
                bool spinning,
                SimDrone* out,
                io::BagFormat format = io::BagFormat::kRos1) {
  sim::Scenario scenario;
  SWARMLIO_RETURN_IF_ERROR(sim::LoadScenario(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml", &scenario));
  sim::SimulationConfig config = scenario.simulation_config();
  config.duration_s = kDurationS;
  config.num_threads = 1;
  scenario.drones.resize(1);
  sim::DroneConfig& drone = scenario.drones[0];
  if (spinning) {
    ImuOptions unused_imu;
    SWARMLIO_RETURN_IF_ERROR(config::LoadSensorPreset(
        std::string(SWARMLIO_SOURCE_DIR) + "/configs/spinning_32.yaml", &drone.lidar.sensor,
        &unused_imu));
    drone.lidar.sensor.points_per_second = 192000;  // 0.6 deg azimuth steps: a faster test
  }
  scenario.bag.format = format;
  out->bag = (dir / sim::BagFileName(name, scenario.bag)).string();
  const driver::DroneInput given = swarmlio::testing::GivenDroneInput(drone);
  out->lidar = given.lidar;
  out->imu = given.imu;
  out->imu_time_offset_s = given.odometry.imu_time_offset_s;
  std::unique_ptr<sim::DroneOutputWriter> writer;
  SWARMLIO_RETURN_IF_ERROR(sim::DroneOutputWriter::Open(
      out->bag, (dir / (name + "_gt.txt")).string(),
      sim::BagOptionsFor(scenario.bag, drone.lidar.sensor), &writer));
  sim::Simulator simulator(std::move(scenario.scene), scenario.drones, scenario.objects, config);
  std::vector<sim::DroneStats> stats;
  std::vector<sim::DroneSink*> sinks = {writer.get()};
  SWARMLIO_RETURN_IF_ERROR(simulator.Run(sinks, &stats));
  return writer->Close();
}

// What Rewrite changes.
struct Edits {
  bool flip_acceleration = false;
  Eigen::Isometry3d T_W_G = Eigen::Isometry3d::Identity();  // ground truth moved into W
};

// Copies `in` to `out` record by record, applying `edits`, with the writer
// options `options` (topics, message types, point time field).
Status Rewrite(const std::string& in, const std::string& out, const io::BagWriterOptions& options,
               const Edits& edits) {
  io::BagReaderOptions read;
  read.ground_truth_topic = io::kAutoTopic;
  read.point_time_unit = options.point_time_unit;  // the original's (same as written)
  std::unique_ptr<io::BagReader> reader;
  SWARMLIO_RETURN_IF_ERROR(io::BagReader::Open(in, read, &reader));
  std::unique_ptr<io::BagWriter> writer;
  SWARMLIO_RETURN_IF_ERROR(io::BagWriter::Open(out, options, &writer));
  const Eigen::Quaterniond q_W_G(edits.T_W_G.linear());
  while (true) {
    io::BagRecord record;
    bool has = false;
    SWARMLIO_RETURN_IF_ERROR(reader->Next(&record, &has));
    if (!has) break;
    if (ImuSample* imu = std::get_if<ImuSample>(&record.data)) {
      if (edits.flip_acceleration) imu->linear_acceleration = -imu->linear_acceleration;
      SWARMLIO_RETURN_IF_ERROR(writer->WriteImu(*imu));
    } else if (LidarScan* scan = std::get_if<LidarScan>(&record.data)) {
      SWARMLIO_RETURN_IF_ERROR(writer->WriteScan(*scan));
    } else if (PoseStamped* pose = std::get_if<PoseStamped>(&record.data)) {
      pose->p_b_in_G = edits.T_W_G * pose->p_b_in_G;
      pose->q_G_b = q_W_G * pose->q_G_b;
      SWARMLIO_RETURN_IF_ERROR(writer->WriteGroundTruth(*pose));
    }
  }
  return writer->Close();
}

struct RunResult {
  double rmse_m = 0.0;  // vs the original ground truth (in G)
  eval::Trajectory estimate;
  eval::FrameCheck frame;
  lio::ImuInitialization init;
  io::ReadStats stats;
  std::string imu_topic, lidar_topic, ground_truth_topic;
};

class ForeignBagTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("swarmlio_foreign_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    ASSERT_TRUE(Simulate(*dir_, "mid360", false, &mid360_).ok());
    ASSERT_TRUE(Simulate(*dir_, "spinning", true, &spinning_).ok());
    // The original ground truth, in G (the simulator writes T_G_b).
    io::BagReaderOptions read;
    std::unique_ptr<io::BagReader> reader;
    ASSERT_TRUE(io::BagReader::Open(mid360_.bag, read, &reader).ok());
    read.point_time_unit = spinning_.lidar.timestamp_unit;
    truth_mid360_ = new std::vector<PoseStamped>;
    for (io::BagRecord r; ;) {
      bool has = false;
      ASSERT_TRUE(reader->Next(&r, &has).ok());
      if (!has) break;
      if (const PoseStamped* p = std::get_if<PoseStamped>(&r.data)) truth_mid360_->push_back(*p);
    }
    ASSERT_TRUE(io::BagReader::Open(spinning_.bag, read, &reader).ok());
    truth_spinning_ = new std::vector<PoseStamped>;
    for (io::BagRecord r; ;) {
      bool has = false;
      ASSERT_TRUE(reader->Next(&r, &has).ok());
      if (!has) break;
      if (const PoseStamped* p = std::get_if<PoseStamped>(&r.data)) truth_spinning_->push_back(*p);
    }
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete truth_mid360_;
    delete truth_spinning_;
  }

  // A manifest entry as a newcomer would write it: the bag and the sensor
  // description; topics found by type ("" = auto), ground truth "auto".
  static driver::DroneInput Input(const SimDrone& d, const std::string& bag) {
    driver::DroneInput in;
    in.name = "uav1";
    in.bag_path = bag;
    in.lidar = d.lidar;
    in.imu = d.imu;
    in.bag.imu_topic = "";
    in.bag.lidar_topic = "";
    in.bag.ground_truth_topic = io::kAutoTopic;
    in.bag.point_time_unit = d.lidar.timestamp_unit;
    in.bag.spinning_lidar = d.lidar.type == LidarType::kSpinning;
    in.odometry = driver::DefaultOdometryOptions(d.lidar, d.imu);
    in.odometry.imu_time_offset_s = d.imu_time_offset_s;
    return in;
  }

  static RunResult Run(const driver::DroneInput& input, const std::vector<PoseStamped>& truth) {
    RunResult result;
    driver::SwarmManifest manifest;
    manifest.name = "foreign";
    manifest.drones = {input};
    std::unique_ptr<SwarmReplay> run;
    const Status created = SwarmReplay::Create(manifest, &run);
    EXPECT_TRUE(created.ok()) << created.message();
    if (!created.ok()) return result;
    const Status status = run->Run(ReplayOptions());
    EXPECT_TRUE(status.ok()) << status.message();
    const DroneRunner& d = run->drone(0);
    EXPECT_TRUE(d.estimator().initialized()) << d.estimator().initialization_error();
    result.init = d.estimator().initialization();
    result.stats = d.reader().stats();
    result.imu_topic = d.reader().imu_topic();
    result.lidar_topic = d.reader().lidar_topic();
    result.ground_truth_topic = d.reader().ground_truth_topic();
    eval::ConsistencyStats cs;
    EXPECT_TRUE(eval::EvaluateConsistency(UpdatedEstimate(d.scans()),
                                          eval::TrajectoryFromPoses(truth), 0.05, &cs)
                    .ok());
    result.rmse_m = cs.position_rmse_m;
    result.estimate = UpdatedEstimate(d.scans()).poses;
    if (!d.bag_ground_truth().empty()) {
      EXPECT_TRUE(eval::CheckGroundTruthFrame(UpdatedEstimate(d.scans()).poses,
                                              eval::TrajectoryFromPoses(d.bag_ground_truth()),
                                              input.ground_truth_frame, eval::FrameCheckOptions(),
                                              &result.frame)
                      .ok());
    }
    return result;
  }

  // The same flight simulated into a ROS 2 log of `format`: replayed, the
  // trajectory equals the ROS1 bag's to 1e-9 m.
  static void ExpectSameAsTheRos1Bag(io::BagFormat format, const std::string& extension);

  static fs::path* dir_;
  static SimDrone mid360_, spinning_;
  static std::vector<PoseStamped>* truth_mid360_;
  static std::vector<PoseStamped>* truth_spinning_;
};

fs::path* ForeignBagTest::dir_ = nullptr;
SimDrone ForeignBagTest::mid360_;
SimDrone ForeignBagTest::spinning_;
std::vector<PoseStamped>* ForeignBagTest::truth_mid360_ = nullptr;
std::vector<PoseStamped>* ForeignBagTest::truth_spinning_ = nullptr;

// (a) a driver that reports -(specific force), and (c) other topic names
// with the ground truth in a mocap-like world frame.
TEST_F(ForeignBagTest, SignFlippedImuAndForeignTopicsTrackLikeTheOriginal) {
  const RunResult normal = Run(Input(mid360_, mid360_.bag), *truth_mid360_);
  EXPECT_EQ(normal.init.reported_direction, lio::SpecificForceDirection::kUp);
  EXPECT_TRUE(normal.init.sign_warning.empty()) << normal.init.sign_warning;
  EXPECT_TRUE(normal.frame.same_frame) << normal.frame.Summary();

  io::BagWriterOptions same = sim::BagOptionsFor(io::BagWriterOptions(), mid360_.lidar);
  const std::string flipped_bag = (*dir_ / "flipped.bag").string();
  Edits flip;
  flip.flip_acceleration = true;
  ASSERT_TRUE(Rewrite(mid360_.bag, flipped_bag, same, flip).ok());
  driver::DroneInput flipped_input = Input(mid360_, flipped_bag);
  flipped_input.odometry.imu_init.acceleration_sign = 0;  // auto
  const RunResult flipped = Run(flipped_input, *truth_mid360_);
  EXPECT_EQ(flipped.init.reported_direction, lio::SpecificForceDirection::kDown);
  EXPECT_TRUE(flipped.init.sign_detected);
  EXPECT_EQ(flipped.init.acceleration_sign, -1);

  io::BagWriterOptions renamed = same;
  renamed.imu_topic = "/mavros/imu/data";
  renamed.lidar_topic = "/sensors/lidar_points";
  renamed.ground_truth_topic = "/vicon/uav1/odom";
  renamed.ground_truth_format = io::GroundTruthFormat::kOdometry;
  Edits mocap;  // ground truth in a world frame 3 m away, rotated 90 deg
  mocap.T_W_G.linear() = so3::Exp(Eigen::Vector3d(0.0, 0.0, M_PI / 2));
  mocap.T_W_G.translation() = Eigen::Vector3d(3.0, -1.0, 0.5);
  const std::string renamed_bag = (*dir_ / "renamed.bag").string();
  ASSERT_TRUE(Rewrite(mid360_.bag, renamed_bag, renamed, mocap).ok());
  const RunResult foreign = Run(Input(mid360_, renamed_bag), *truth_mid360_);
  EXPECT_EQ(foreign.imu_topic, "/mavros/imu/data");
  EXPECT_EQ(foreign.lidar_topic, "/sensors/lidar_points");
  EXPECT_EQ(foreign.ground_truth_topic, "/vicon/uav1/odom");
  EXPECT_TRUE(foreign.frame.compared);
  EXPECT_FALSE(foreign.frame.same_frame);
  EXPECT_NE(foreign.frame.Summary().find("another frame: aligned by first pose and SE(3)"),
            std::string::npos);

  std::printf("[ figures  ] position RMSE: original %.4f m, sign-flipped %.4f m, renamed %.4f m\n",
              normal.rmse_m, flipped.rmse_m, foreign.rmse_m);
  // Measured 0.0018 m each (Release, the given calibration; 0.0022 m with the true one).
  EXPECT_LT(normal.rmse_m, 0.005);
  EXPECT_LT(flipped.rmse_m, 2.0 * normal.rmse_m);
  EXPECT_LT(foreign.rmse_m, 2.0 * normal.rmse_m);
}

// (b) a spinning LiDAR whose driver publishes no per-point time: the reader
// reconstructs it from azimuth.
TEST_F(ForeignBagTest, SpinningCloudWithoutPointTimeTracksLikeTheOriginal) {
  const RunResult timed = Run(Input(spinning_, spinning_.bag), *truth_spinning_);
  EXPECT_EQ(timed.stats.scans_without_point_time, 0);

  io::BagWriterOptions no_time = sim::BagOptionsFor(io::BagWriterOptions(), spinning_.lidar);
  no_time.write_point_time = false;
  const std::string no_time_bag = (*dir_ / "spinning_no_time.bag").string();
  ASSERT_TRUE(Rewrite(spinning_.bag, no_time_bag, no_time, Edits()).ok());
  const RunResult reconstructed = Run(Input(spinning_, no_time_bag), *truth_spinning_);
  EXPECT_GT(reconstructed.stats.scans_without_point_time, 0);
  EXPECT_EQ(reconstructed.stats.scans_point_time_from_azimuth,
            reconstructed.stats.scans_without_point_time);

  driver::DroneInput instant_input = Input(spinning_, no_time_bag);
  instant_input.bag.reconstruct_point_time = io::PointTimeReconstruction::kNone;
  const RunResult instant = Run(instant_input, *truth_spinning_);
  EXPECT_EQ(instant.stats.scans_point_time_from_azimuth, 0);

  std::printf("[ figures  ] spinning position RMSE: per-point time %.4f m, from azimuth %.4f m, "
              "one instant %.4f m\n",
              timed.rmse_m, reconstructed.rmse_m, instant.rmse_m);
  // Measured (Release, the given calibration): per-point time 0.0053 m, from
  // azimuth 0.0053 m, one instant 0.0188 m (with the true calibration 0.0045,
  // 0.0044 and 0.0176 m). The reconstruction recovers the undistortion, so no
  // slack beyond the 2x bound is needed; reading one instant is 3.5x worse.
  EXPECT_LT(timed.rmse_m, 0.015);
  EXPECT_LT(reconstructed.rmse_m, 2.0 * timed.rmse_m);
  EXPECT_LT(reconstructed.rmse_m, instant.rmse_m);
}

// The same flight simulated into a ROS1 bag and into a ROS 2 log of CDR
// messages (an MCAP file, a rosbag2 .db3 file): replayed, the trajectories
// are the same to 1e-9 m.
TEST_F(ForeignBagTest, SameFlightFromMcapGivesTheSameTrajectory) {
  ExpectSameAsTheRos1Bag(io::BagFormat::kMcap, ".mcap");
}

TEST_F(ForeignBagTest, SameFlightFromDb3GivesTheSameTrajectory) {
  ExpectSameAsTheRos1Bag(io::BagFormat::kDb3, ".db3");
}

void ForeignBagTest::ExpectSameAsTheRos1Bag(io::BagFormat format, const std::string& extension) {
  SimDrone mcap;
  ASSERT_TRUE(Simulate(*dir_, "mid360_ros2" + extension.substr(1), false, &mcap, format).ok());
  ASSERT_EQ(fs::path(mcap.bag).extension(), extension);
  const RunResult from_bag = Run(Input(mid360_, mid360_.bag), *truth_mid360_);
  const RunResult from_mcap = Run(Input(mcap, mcap.bag), *truth_mid360_);
  EXPECT_EQ(from_mcap.imu_topic, "/livox/imu");
  EXPECT_EQ(from_mcap.stats.ToString(), from_bag.stats.ToString());
  ASSERT_GT(from_bag.estimate.size(), 10u);
  ASSERT_EQ(from_mcap.estimate.size(), from_bag.estimate.size());
  double max_difference_m = 0.0;
  for (size_t i = 0; i < from_bag.estimate.size(); ++i) {
    EXPECT_EQ(from_mcap.estimate.stamps_s[i], from_bag.estimate.stamps_s[i]) << i;
    max_difference_m = std::max(max_difference_m, (from_mcap.estimate.T_G_b[i].translation() -
                                                   from_bag.estimate.T_G_b[i].translation())
                                                      .norm());
  }
  EXPECT_LE(max_difference_m, 1e-9);
  EXPECT_EQ(from_mcap.rmse_m, from_bag.rmse_m);
}

}  // namespace
}  // namespace swarmlio::replay
