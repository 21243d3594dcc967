// End to end: what the simulator emits, written by DroneOutputWriter to a ROS1
// bag, is read back by the streaming BagReader record for record, exactly.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/sim/output_writer.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::sim {
namespace {

namespace fs = std::filesystem;

// Records everything and forwards it to a writer.
class TeeSink : public DroneSink {
 public:
  explicit TeeSink(DroneSink* next) : next_(next) {}
  Status OnImu(const ImuSample& imu) override {
    imu_.push_back(imu);
    return next_->OnImu(imu);
  }
  Status OnScan(const LidarScan& scan, int64_t record_time_ns) override {
    scans_.push_back(scan);
    return next_->OnScan(scan, record_time_ns);
  }
  Status OnGroundTruth(const PoseStamped& pose) override {
    poses_.push_back(pose);
    return next_->OnGroundTruth(pose);
  }
  std::vector<ImuSample> imu_;
  std::vector<LidarScan> scans_;
  std::vector<PoseStamped> poses_;

 private:
  DroneSink* next_;
};

void ExpectSamePoints(const LidarScan& a, const LidarScan& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i) {
    const LidarPoint& p = a.points[i];
    const LidarPoint& q = b.points[i];
    ASSERT_EQ(p.x, q.x);
    ASSERT_EQ(p.y, q.y);
    ASSERT_EQ(p.z, q.z);
    ASSERT_EQ(p.reflectivity, q.reflectivity);
    ASSERT_EQ(p.offset_time_s, q.offset_time_s);
    ASSERT_EQ(p.tag, q.tag);
    ASSERT_EQ(p.line, q.line);
  }
}

TEST(SimulatorOutput, BagsReadBackExactly) {
  Scenario scenario;
  const std::string path = std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml";
  ASSERT_TRUE(LoadScenario(path, &scenario).ok());
  SimulationConfig config = scenario.simulation_config();
  config.duration_s = 1.2;
  const fs::path dir = fs::temp_directory_path() / ("swarmlio_sim_rt_" + std::to_string(::getpid()));
  fs::create_directories(dir);

  const size_t n = scenario.drones.size();
  std::vector<std::unique_ptr<DroneOutputWriter>> writers(n);
  std::vector<std::unique_ptr<TeeSink>> tees;
  std::vector<DroneSink*> sinks;
  std::vector<io::BagWriterOptions> bag_options;
  for (size_t i = 0; i < n; ++i) {
    bag_options.push_back(BagOptionsFor(scenario.bag, scenario.drones[i].lidar.sensor));
    const std::string stem = (dir / scenario.drones[i].name).string();
    ASSERT_TRUE(
        DroneOutputWriter::Open(stem + ".bag", stem + ".tum", bag_options[i], &writers[i]).ok());
    tees.push_back(std::make_unique<TeeSink>(writers[i].get()));
    sinks.push_back(tees.back().get());
  }
  Simulator simulator(std::move(scenario.scene), scenario.drones, scenario.objects, config);
  std::vector<DroneStats> stats;
  ASSERT_TRUE(simulator.Run(sinks, &stats).ok());
  for (auto& w : writers) ASSERT_TRUE(w->Close().ok());

  for (size_t i = 0; i < n; ++i) {
    SCOPED_TRACE(scenario.drones[i].name);
    io::BagReaderOptions read_options;
    read_options.imu_topic = bag_options[i].imu_topic;
    read_options.lidar_topic = bag_options[i].lidar_topic;
    read_options.ground_truth_topic = bag_options[i].ground_truth_topic;
    read_options.point_time_unit = bag_options[i].point_time_unit;
    std::unique_ptr<io::BagReader> reader;
    const std::string bag = (dir / (scenario.drones[i].name + ".bag")).string();
    ASSERT_TRUE(io::BagReader::Open(bag, read_options, &reader).ok());
    size_t imu = 0, scans = 0, poses = 0;
    int64_t last_stamp = 0;
    io::BagRecord record;
    bool has = true;
    while (true) {
      ASSERT_TRUE(reader->Next(&record, &has).ok());
      if (!has) break;
      ASSERT_GE(record.stamp_ns(), last_stamp) << "records must come in stamp order";
      last_stamp = record.stamp_ns();
      if (const ImuSample* s = record.imu()) {
        ASSERT_LT(imu, tees[i]->imu_.size());
        const ImuSample& e = tees[i]->imu_[imu++];
        EXPECT_EQ(s->stamp_ns, e.stamp_ns);
        EXPECT_EQ(s->angular_velocity_rad_s, e.angular_velocity_rad_s);
        EXPECT_EQ(s->linear_acceleration, e.linear_acceleration);
      } else if (const LidarScan* sc = record.scan()) {
        ASSERT_LT(scans, tees[i]->scans_.size());
        const LidarScan& e = tees[i]->scans_[scans++];
        EXPECT_EQ(sc->stamp_ns, e.stamp_ns);
        ExpectSamePoints(*sc, e);
      } else if (const PoseStamped* ps = record.ground_truth()) {
        ASSERT_LT(poses, tees[i]->poses_.size());
        const PoseStamped& e = tees[i]->poses_[poses++];
        EXPECT_EQ(ps->stamp_ns, e.stamp_ns);
        EXPECT_EQ(ps->p_b_in_G, e.p_b_in_G);
        EXPECT_EQ(ps->q_G_b.coeffs(), e.q_G_b.coeffs());
      }
    }
    EXPECT_EQ(imu, tees[i]->imu_.size());
    EXPECT_EQ(scans, tees[i]->scans_.size());
    EXPECT_EQ(poses, tees[i]->poses_.size());
    EXPECT_GT(scans, 5u);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmlio::sim
