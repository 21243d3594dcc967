// swarmlio_ros against a real rosmaster on loopback: a simulated drone's bag
// (indoor_3uav uav1, simulated for kDurationS seconds) is published in real time
// by swarmlio_bag_publisher, with each scan sent kLidarDelayS after its stamp
// (as a driver publishes at the scan end, so the two topics interleave out
// of stamp order); swarmlio_ros runs the drone and writes its odometry; the
// test also subscribes to ~odometry. The offline replay of the same bag
// (SwarmReplay, the drone alone) is the reference: every scan must come out
// (none dropped), at the same stamps, within 1 mm. Once per input ordering
// (live::PushSource): `stamp` puts the two streams back in the bag reader's
// order, so the estimator sees exactly the replay's record sequence;
// `imu_first` (the node's default, low latency) releases IMU samples on
// arrival and a scan once the IMU passed its stamp, and the odometry, which
// buffers a scan until the IMU passes its end and consumes the IMU in stamp
// order, must give the same estimate. A dropped scan, or a record reordered
// in a way the odometry notices, changes the estimate or the stamps and
// fails the test (with `stamp` and --max_wait_ms 0, i.e. arrival order,
// every scan comes late and is dropped). The node's waits are generous (4 s)
// so that a test machine busy with other tests does not release records
// early. The node's latency line (scan end -> ~odometry) is printed, not
// asserted.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <netinet/in.h>
#include <ros/ros.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "swarmlio/driver/manifest.h"
#include "swarmlio/replay/swarm_replay.h"
#include "test_utils/free_port.h"
#include "test_utils/temp_dir.h"

extern char** environ;

namespace swarmlio {
namespace {

constexpr double kDurationS = 12.0;    // of the bag, published in real time
constexpr double kLidarDelayS = 0.1;   // each scan published this late (a scan period)
constexpr double kToleranceM = 1e-3;   // the 1 mm

// A child process with stdout and stderr in `log`; killed (SIGTERM, then
// SIGKILL) and reaped when destroyed.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::string& log) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() { Kill(); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool started() const { return pid_ > 0; }
  /// Waits up to `timeout_s` for the exit; true with its exit code.
  bool Wait(double timeout_s, int* exit_code) {
    const auto give_up = std::chrono::steady_clock::now() +
                         std::chrono::milliseconds(static_cast<int64_t>(timeout_s * 1e3));
    while (pid_ > 0) {
      int status = 0;
      const pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        pid_ = -1;
        *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return true;
      }
      if (std::chrono::steady_clock::now() > give_up) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  void Kill() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    int code = 0;
    if (!Wait(5.0, &code)) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
};

bool Listening(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<uint16_t>(port));
  const bool ok = connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
  close(fd);
  return ok;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Pose {
  double stamp_s = 0.0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

std::vector<Pose> ReadTum(const std::string& path) {
  std::vector<Pose> poses;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream row(line);
    Pose pose;
    row >> pose.stamp_s >> pose.p.x() >> pose.p.y() >> pose.p.z();
    if (row) poses.push_back(pose);
  }
  return poses;
}

// Max position difference of `poses` against `reference` paired by stamp
// (within 1 us); counts the poses without a partner.
double MaxDifference(const std::vector<Pose>& poses, const std::vector<swarm::DroneOutput>& reference,
                     int* unpaired) {
  double max_dp = 0.0;
  *unpaired = 0;
  for (const Pose& pose : poses) {
    const auto it = std::find_if(reference.begin(), reference.end(), [&](const auto& r) {
      return std::abs(ToSeconds(r.ego.stamp_ns) - pose.stamp_s) < 1e-6;
    });
    if (it == reference.end()) {
      ++*unpaired;
      continue;
    }
    max_dp = std::max(max_dp, (it->ego.state.p_b_in_G - pose.p).norm());
  }
  return max_dp;
}

// The node's --ordering value.
class RosNodeTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RosNodeTest, OdometryOverRosmasterEqualsOfflineReplay) {
  const auto t0 = std::chrono::steady_clock::now();
  testing::TempDir dir;
  const std::string root = dir.path().string();
  int code = -1;

  // The drone's bag and its manifest.
  {
    Child sim({SWARMLIO_SIM, "--scenario", std::string(SWARMLIO_SOURCE_DIR) +
                                               "/configs/scenarios/indoor_3uav.yaml",
               "--imperfections", "ideal", "--seed", "1", "--duration_s",
               std::to_string(kDurationS), "--output_dir", root + "/sim"},
              root + "/sim.log");
    ASSERT_TRUE(sim.Wait(300.0, &code)) << ReadFile(root + "/sim.log");
    ASSERT_EQ(code, 0) << ReadFile(root + "/sim.log");
  }
  // The reference: the offline replay of uav1 alone (registered clouds on,
  // as the node runs).
  driver::SwarmManifest manifest;
  Status s = driver::LoadManifest(root + "/sim/swarm.yaml", &manifest);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_GE(manifest.drones.size(), 1u);
  ASSERT_EQ(manifest.drones[0].name, "uav1");
  manifest.drones.resize(1);
  manifest.drones[0].odometry.output_registered_scan = true;
  std::unique_ptr<replay::SwarmReplay> offline;
  s = replay::SwarmReplay::Create(manifest, &offline);
  ASSERT_TRUE(s.ok()) << s.message();
  s = offline->Run(replay::ReplayOptions());
  ASSERT_TRUE(s.ok()) << s.message();
  const std::vector<swarm::DroneOutput>& reference = offline->drone(0).scans();
  ASSERT_FALSE(reference.empty());

  // rosmaster on a free loopback port; every process talks over 127.0.0.1.
  const int master_port = swarmlio::testing::FreeLoopbackPort(SOCK_STREAM);
  ASSERT_GT(master_port, 0);
  const std::string master_uri = "http://127.0.0.1:" + std::to_string(master_port) + "/";
  setenv("ROS_MASTER_URI", master_uri.c_str(), 1);
  setenv("ROS_IP", "127.0.0.1", 1);
  unsetenv("ROS_HOSTNAME");
  setenv("ROS_HOME", (root + "/ros_home").c_str(), 1);
  setenv("ROS_LOG_DIR", (root + "/ros_log").c_str(), 1);
  Child master({SWARMLIO_ROSMASTER, "--core", "-p", std::to_string(master_port)},
               root + "/rosmaster.log");
  ASSERT_TRUE(master.started());
  for (int i = 0; i < 500 && !Listening(master_port); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(Listening(master_port)) << ReadFile(root + "/rosmaster.log");

  // This process subscribes to the node's odometry.
  ros::M_string remappings{{"__master", master_uri}, {"__ip", "127.0.0.1"}};
  ros::init(remappings, "swarmlio_ros_test", ros::init_options::NoSigintHandler);
  std::mutex mutex;
  std::vector<Pose> received;
  {
    ros::NodeHandle node;
    ros::Subscriber subscriber = node.subscribe<nav_msgs::Odometry>(
        "/swarmlio_ros/odometry", 1000, [&](const nav_msgs::Odometry::ConstPtr& m) {
          Pose pose;
          pose.stamp_s = ToSeconds(static_cast<int64_t>(m->header.stamp.toNSec()));
          pose.p = {m->pose.pose.position.x, m->pose.pose.position.y, m->pose.pose.position.z};
          std::lock_guard<std::mutex> lock(mutex);
          received.push_back(pose);
        });
    ros::AsyncSpinner spinner(1);
    spinner.start();

    const std::string key_path = root + "/swarm.key";
    std::ofstream(key_path) << std::string(64, '5') << "\n";
    Child node_process(
        {SWARMLIO_ROS_NODE, "--manifest", root + "/sim/swarm.yaml", "--drone", "uav1",
         "--key_file", key_path, "--udp_mode", "unicast", "--interface_address", "127.0.0.1",
         "--port", std::to_string(swarmlio::testing::FreeLoopbackPort(SOCK_DGRAM)), "--peers",
         "uav2=127.0.0.1:" + std::to_string(swarmlio::testing::FreeLoopbackPort(SOCK_DGRAM)), "--output_dir",
         root + "/node", "--idle_timeout_s", "4", "--max_scan_backlog_s", "30",
         "--max_queued_scans", "1000", "--max_buffered_scans", "1000", "--max_wait_ms", "4000",
         "--ordering", GetParam()},
        root + "/node.log");
    ASSERT_TRUE(node_process.started());
    Child publisher({SWARMLIO_BAG_PUBLISHER, "--bag", root + "/sim/uav1.bag", "--lidar_delay_s",
                     std::to_string(kLidarDelayS),
                     "--wait_for_subscribers_s", "60"},
                    root + "/publisher.log");
    ASSERT_TRUE(publisher.Wait(kDurationS + 120.0, &code)) << ReadFile(root + "/publisher.log");
    EXPECT_EQ(code, 0) << ReadFile(root + "/publisher.log");
    ASSERT_TRUE(node_process.Wait(120.0, &code)) << ReadFile(root + "/node.log");
    EXPECT_EQ(code, 0) << ReadFile(root + "/node.log");
    spinner.stop();
  }
  ros::shutdown();
  master.Kill();
  std::printf("%s%s", ReadFile(root + "/publisher.log").c_str(),
              ReadFile(root + "/node.log").c_str());

  const std::vector<Pose> written = ReadTum(root + "/node/uav1_tum.txt");
  ASSERT_FALSE(written.empty());
  // Every scan of the replay, no more (a dropped scan is missing here).
  EXPECT_EQ(written.size(), reference.size());
  EXPECT_GT(ToSeconds(reference.back().ego.stamp_ns - reference.front().ego.stamp_ns),
            kDurationS - 2.0);
  int unpaired = 0;
  const double max_written_m = MaxDifference(written, reference, &unpaired);
  EXPECT_EQ(unpaired, 0);
  EXPECT_LE(max_written_m, kToleranceM);
  // What came over the topic: the same (allowing the last few to miss the
  // shutdown), nothing else.
  int unpaired_received = 0;
  const double max_received_m = MaxDifference(received, reference, &unpaired_received);
  EXPECT_GE(received.size() + 3, reference.size());
  EXPECT_EQ(unpaired_received, 0);
  EXPECT_LE(max_received_m, kToleranceM);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("ros node (%s order) vs offline replay: %zu scans, %zu odometry messages "
              "received; max position difference %.3g mm (file), %.3g mm (topic); test %.1f s\n",
              GetParam().c_str(), written.size(), received.size(), 1e3 * max_written_m,
              1e3 * max_received_m, elapsed_s);
}

INSTANTIATE_TEST_SUITE_P(Ordering, RosNodeTest, ::testing::Values("stamp", "imu_first"),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           return param.param == "stamp" ? std::string("Stamp")
                                                         : std::string("ImuFirst");
                         });

}  // namespace
}  // namespace swarmlio
