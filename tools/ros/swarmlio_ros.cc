// swarmlio_ros: ONE drone of the live swarm as a ROS1 node (docs/online.md,
// "ROS node"). The same live component as swarmlio_live (live::LiveDrone:
// estimator and network threads, the same UDP swarm protocol), fed by the
// drone's sensor topics instead of a bag: IMU (sensor_msgs/Imu) and LiDAR
// (Livox CustomMsg or sensor_msgs/PointCloud2) are subscribed raw, decoded
// by the project's decoders and ordered by live::PushSource (--ordering). The
// sensor time line is the messages' header stamps (ROS time).
// Publishes odometry, path, clouds, teammates and TF (ros_outputs.h);
// --output_dir also writes swarmlio_live's files.
//
//   swarmlio_ros --manifest=swarm.yaml --drone=uav1 --key_file=swarm.key
//   swarmlio_ros --sensor_preset=configs/livox_mid360.yaml --drone_id=0 --name=uav1
//       --key_file=swarm.key --imu_topic=/mavros/imu/data --lidar_topic=/livox/lidar
// (ROS remappings and __name:=... are accepted as usual.)
#include <gflags/gflags.h>
#include <ros/ros.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "live_flags.h"
#include "live_outputs.h"
#include "live_summary.h"
#include "ros_input.h"
#include "ros_outputs.h"
#include "swarmlio/live/live_drone.h"
#include "swarmlio/live/push_source.h"
#include "swarmlio/live/steady_clock.h"
#include "swarmlio/net/udp_transport.h"

DEFINE_string(imu_topic, "", "IMU topic (default: the manifest's bag_topics.imu_topic, /livox/imu)");
DEFINE_string(lidar_topic, "",
              "LiDAR topic (default: the manifest's bag_topics.lidar_topic, /livox/lidar)");
DEFINE_string(world_frame, "world", "frame id of the drone's global frame G (odometry, clouds)");
DEFINE_string(body_frame, "body", "frame id of the body (IMU) frame");
DEFINE_double(local_map_period_s, 1.0, "publish ~local_map this often [s]; 0 = never");
DEFINE_int32(max_path_poses, 3000, "~path keeps the last poses");
DEFINE_bool(tf, true, "publish world -> body on /tf");
DEFINE_bool(registered_cloud, true, "publish ~cloud_registered (the scan in the world frame)");
DEFINE_bool(imu_odom, true, "publish ~odometry_imu (the IMU-rate propagated state)");
DEFINE_string(ordering, "imu_first",
              "input order: imu_first (IMU samples on arrival, a scan once the IMU passed its "
              "stamp: odometry right after the scan's IMU) or stamp (the bag reader's order "
              "exactly, about one scan period later; docs/online.md)");
DEFINE_double(max_wait_ms, 500.0,
              "a record waits at most this long for the other sensor stream to pass its stamp "
              "(> scan period + transport delay) [ms]");
DEFINE_int32(max_buffered_scans, 8, "scans waiting to be ordered; more are dropped");
DEFINE_double(idle_timeout_s, 0.0,
              "end (flush and exit) when no sensor message came for this long after the first "
              "[s]; 0 = run until Ctrl-C / rosnode kill");
DEFINE_string(output_dir, "", "also write swarmlio_live's files here (created); \"\" = none");

namespace swarmlio::tools {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnSignal(int) { g_interrupted = true; }

int Fail(const Status& status) {
  std::fprintf(stderr, "error: %s\n", status.message().c_str());
  return 1;
}

int64_t WallNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string InputSummary(const RosInput& input, const live::PushSource& source,
                         const char* ordering) {
  const RosInputStats in = input.stats();
  const live::PushSourceStats p = source.stats();
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "  ROS input: %lld IMU and %lld LiDAR messages, %lld rejected%s%s; decoder "
                "skipped %lld\n"
                "  input order %s: %lld released (%lld by timeout or a full buffer), late %lld IMU / "
                "%lld scans, scans dropped (buffer full) %lld, IMU pushes waited %lld\n",
                static_cast<long long>(in.imu_messages), static_cast<long long>(in.lidar_messages),
                static_cast<long long>(in.rejected), in.first_error.empty() ? "" : "; first: ",
                in.first_error.c_str(),
                static_cast<long long>(input.read_stats().TotalSkipped()), ordering,
                static_cast<long long>(p.released), static_cast<long long>(p.released_by_timeout),
                static_cast<long long>(p.imu_late), static_cast<long long>(p.scans_late),
                static_cast<long long>(p.scans_dropped_full),
                static_cast<long long>(p.imu_push_waits));
  return buffer;
}

int Main() {
  driver::SwarmManifest manifest;
  driver::DroneInput drone;
  int drone_id = 0;
  Status status = LoadDroneFromFlags(LiveInput::kTopics, &drone, &drone_id, &manifest);
  if (!status.ok()) return Fail(status);
  live::LiveSetup setup;
  status = SwarmKeyFromFlags(&setup.key);
  if (!status.ok()) return Fail(status);
  net::UdpOptions udp_options;
  status = UdpOptionsFromFlags(manifest, &udp_options);
  if (!status.ok()) return Fail(status);

  RosInputOptions input_options;
  input_options.imu_topic = FLAGS_imu_topic.empty() ? drone.bag.imu_topic : FLAGS_imu_topic;
  input_options.lidar_topic = FLAGS_lidar_topic.empty() ? drone.bag.lidar_topic : FLAGS_lidar_topic;
  RosOutputOptions output_options;
  output_options.world_frame = FLAGS_world_frame;
  output_options.body_frame = FLAGS_body_frame;
  output_options.local_map_period_s = FLAGS_local_map_period_s;
  output_options.max_path_poses = FLAGS_max_path_poses;
  output_options.publish_tf = FLAGS_tf;
  live::PushSourceOptions push_options;
  if (!config::EnumFromString(FLAGS_ordering, &push_options.ordering)) {
    return Fail(Status::InvalidArgument("--ordering: '" + FLAGS_ordering + "', expected one of " +
                                        config::EnumChoices<live::PushOrdering>()));
  }
  push_options.max_wait_ms = FLAGS_max_wait_ms;
  push_options.max_buffered_scans = FLAGS_max_buffered_scans;
  for (const std::string& invalid :
       {input_options.Validate(), output_options.Validate(), push_options.Validate()}) {
    if (!invalid.empty()) return Fail(Status::InvalidArgument(invalid));
  }
  live::LiveOptions options;
  ApplyLiveFlags(&options);
  options.imu_rate_odometry = FLAGS_imu_odom || !FLAGS_output_dir.empty();
  drone.odometry.output_registered_scan = FLAGS_registered_cloud;

  live::SteadyClock clock;
  std::unique_ptr<live::PushSource> source;
  status = live::PushSource::Create(push_options, &clock, &source);
  if (!status.ok()) return Fail(status);
  std::unique_ptr<net::UdpTransport> udp;
  status = net::UdpTransport::Create(udp_options, drone_id, &udp);
  if (!status.ok()) return Fail(status);
  std::vector<std::string> drone_names;
  for (const driver::DroneInput& d : manifest.drones) drone_names.push_back(d.name);
  if (static_cast<size_t>(drone_id) >= drone_names.size()) {
    drone_names.resize(static_cast<size_t>(drone_id) + 1);
    drone_names[static_cast<size_t>(drone_id)] = drone.name;
  }
  std::unique_ptr<LiveOutputs> files;
  if (!FLAGS_output_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(FLAGS_output_dir, ec);
    if (ec) return Fail(Status::IoError(FLAGS_output_dir + ": " + ec.message()));
    status = LiveOutputs::Open(FLAGS_output_dir, drone.name, FLAGS_imu_odom, drone_names, &files);
    if (!status.ok()) return Fail(status);
    setup.packet_log_path =
        (std::filesystem::path(FLAGS_output_dir) / (drone.name + "_received.bin")).string();
  }

  ros::NodeHandle root;
  ros::NodeHandle node("~");
  RosOutputs outputs(&node, &root, output_options, drone_names, files.get(), &clock);
  setup.drone = drone;
  setup.drone_id = drone_id;
  setup.transport = udp.get();
  setup.clock = &clock;
  setup.sink = &outputs;
  setup.source = source.get();
  std::unique_ptr<live::LiveDrone> live;
  status = live::LiveDrone::Create(setup, options, &live);
  if (!status.ok()) return Fail(status);
  outputs.set_drone(live.get());
  RosInput input(&root, input_options, drone.bag, 1.0 / drone.lidar.scan_rate_hz, source.get());

  std::printf("%s (id %d): %s on port %d; IMU %s, LiDAR %s; topics under %s; key from %s\n",
              drone.name.c_str(), drone_id, FLAGS_udp_mode.c_str(), udp->local_port(),
              input_options.imu_topic.c_str(), input_options.lidar_topic.c_str(),
              node.getNamespace().c_str(), FLAGS_key_file.c_str());
  std::fflush(stdout);
  ros::AsyncSpinner spinner(1);  // one thread: the two callbacks never run at once
  spinner.start();
  std::atomic<bool> finished{false};
  Status run_status;
  std::thread runner([&] {
    run_status = live->Run();
    finished = true;
  });
  const int64_t idle_ns = static_cast<int64_t>(FLAGS_idle_timeout_s * 1e9);
  while (!finished) {
    const int64_t last_ns = input.last_message_wall_ns();
    const bool idle = idle_ns > 0 && last_ns > 0 && WallNowNs() - last_ns > idle_ns;
    if (g_interrupted || !ros::ok() || idle) {
      source->Close();  // what is buffered is still processed, then the estimator is flushed
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  runner.join();
  // Let the subscribers take the last outputs before the connections close.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  spinner.stop();

  std::string summary = FormatLiveSummary(drone.name, *live, files.get(), udp->stats(), 1.0,
                                          drone_names, &outputs.latencies_ms());
  summary += InputSummary(input, *source, config::EnumToString(push_options.ordering));
  std::printf("%s", summary.c_str());
  Status closed;
  if (files != nullptr) {
    closed = files->Close();
    const std::string path =
        (std::filesystem::path(FLAGS_output_dir) / (drone.name + "_live_summary.txt")).string();
    if (std::FILE* f = std::fopen(path.c_str(), "w")) {
      std::fputs(summary.c_str(), f);
      std::fclose(f);
    }
  }
  ros::shutdown();
  if (!run_status.ok()) return Fail(run_status);
  if (!closed.ok()) return Fail(closed);
  return 0;
}

}  // namespace
}  // namespace swarmlio::tools

int main(int argc, char** argv) {
  // ros::init takes the ROS arguments (remappings, __name:=...) out of argv.
  ros::init(argc, argv, "swarmlio_ros", ros::init_options::NoSigintHandler);
  gflags::SetUsageMessage(
      "one drone of the live swarm as a ROS1 node: sensor topics in, odometry out, UDP swarm "
      "(docs/online.md)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  std::signal(SIGINT, swarmlio::tools::OnSignal);
  std::signal(SIGTERM, swarmlio::tools::OnSignal);
  return swarmlio::tools::Main();
}
