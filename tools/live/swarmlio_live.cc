// swarmlio_live: ONE drone of the live swarm, in real time (x --rate), over a
// real UDP network (docs/online.md). It plays the drone's bag against the
// steady clock, runs its swarm estimator, exchanges messages with the other
// swarmlio_live processes and writes into --output_dir:
//   <name>_tum.txt, <name>_timing.csv (per-scan latency), <name>_imu_odom.csv,
//   <name>_received.bin (every received datagram, for the offline re-run:
//   swarmlio_replay --received_packets <name>=...), <name>_live_summary.txt
//
//   swarmlio_live --manifest=sim/swarm.yaml --drone=uav1 --key_file=swarm.key
//       --udp_mode=unicast --port=9001 --peers=uav2=127.0.0.1:9002,uav3=127.0.0.1:9003
//       --output_dir=out/live
#include <gflags/gflags.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "live_flags.h"
#include "live_outputs.h"
#include "live_summary.h"
#include "swarmlio/live/live_drone.h"
#include "swarmlio/live/steady_clock.h"
#include "swarmlio/net/udp_transport.h"
#include "swarmlio/driver/manifest.h"

DEFINE_double(rate, 1.0, "playback speed (1 = real time)");
DEFINE_double(start_s, 0.0, "skip the log's first seconds (a drone joining late or restarting)");
DEFINE_double(start_at_unix_s, 0.0,
              "start the playback at this wall-clock time (UNIX seconds; 0: at once): processes "
              "started together play the same instant of their logs together");
DEFINE_bool(imu_odom, true, "write <name>_imu_odom.csv (the IMU-rate propagated state)");
DEFINE_string(output_dir, "", "results folder (created)");

namespace swarmlio::tools {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnSignal(int) { g_interrupted = true; }

int Fail(const Status& status) {
  std::fprintf(stderr, "error: %s\n", status.message().c_str());
  return 1;
}

int Main() {
  if (FLAGS_output_dir.empty() || FLAGS_key_file.empty() ||
      (FLAGS_manifest.empty() == FLAGS_bag.empty())) {
    std::fprintf(stderr,
                 "usage: swarmlio_live (--manifest=FILE --drone=NAME | --bag=FILE "
                 "--sensor_preset=FILE [--drone_id=N]) --key_file=FILE --output_dir=DIR "
                 "[--udp_mode=multicast|broadcast|unicast --port=P --peers=id=host:port,...] "
                 "[--rate=1]\n");
    return 2;
  }
  driver::SwarmManifest manifest;
  driver::DroneInput drone;
  int drone_id = 0;
  Status status = LoadDroneFromFlags(LiveInput::kBag, &drone, &drone_id, &manifest);
  if (!status.ok()) return Fail(status);
  live::LiveSetup setup;
  status = SwarmKeyFromFlags(&setup.key);
  if (!status.ok()) return Fail(status);
  net::UdpOptions udp_options;
  status = UdpOptionsFromFlags(manifest, &udp_options);
  if (!status.ok()) return Fail(status);
  live::LiveOptions options;
  options.rate = FLAGS_rate;
  options.start_offset_s = FLAGS_start_s;
  ApplyLiveFlags(&options);
  options.imu_rate_odometry = true;  // counted always; the file is --imu_odom
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_output_dir, ec);
  if (ec) return Fail(Status::IoError(FLAGS_output_dir + ": " + ec.message()));

  std::unique_ptr<net::UdpTransport> udp;
  status = net::UdpTransport::Create(udp_options, drone_id, &udp);
  if (!status.ok()) return Fail(status);
  std::unique_ptr<LiveOutputs> outputs;
  std::vector<std::string> drone_names;
  for (const driver::DroneInput& d : manifest.drones) drone_names.push_back(d.name);
  status = LiveOutputs::Open(FLAGS_output_dir, drone.name, FLAGS_imu_odom, drone_names, &outputs);
  if (!status.ok()) return Fail(status);
  live::SteadyClock clock;
  setup.drone = drone;
  setup.drone_id = drone_id;
  setup.transport = udp.get();
  setup.clock = &clock;
  setup.sink = outputs.get();
  setup.packet_log_path =
      (std::filesystem::path(FLAGS_output_dir) / (drone.name + "_received.bin")).string();
  std::unique_ptr<live::LiveDrone> live;
  status = live::LiveDrone::Create(setup, options, &live);
  if (!status.ok()) return Fail(status);

  std::printf("%s (id %d): %s on port %d, rate %.2f, key from %s\n", drone.name.c_str(), drone_id,
              FLAGS_udp_mode.c_str(), udp->local_port(), FLAGS_rate, FLAGS_key_file.c_str());
  std::fflush(stdout);
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::atomic<bool> finished{false};
  std::thread watcher([&] {
    while (!finished) {
      if (g_interrupted) {
        live->Stop();
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  if (FLAGS_start_at_unix_s > 0.0) {
    const auto start = std::chrono::system_clock::time_point(
        std::chrono::duration_cast<std::chrono::system_clock::duration>(
            std::chrono::duration<double>(FLAGS_start_at_unix_s)));
    while (!g_interrupted && std::chrono::system_clock::now() < start) {
      std::this_thread::sleep_for(
          std::min<std::chrono::system_clock::duration>(start - std::chrono::system_clock::now(),
                                                        std::chrono::milliseconds(50)));
    }
  }
  const Status run_status = live->Run();
  finished = true;
  watcher.join();
  const Status closed = outputs->Close();
  const std::string summary =
      FormatLiveSummary(drone.name, *live, outputs.get(), udp->stats(), FLAGS_rate, drone_names);
  std::printf("%s", summary.c_str());
  const std::string summary_path =
      (std::filesystem::path(FLAGS_output_dir) / (drone.name + "_live_summary.txt")).string();
  if (std::FILE* f = std::fopen(summary_path.c_str(), "w")) {
    std::fputs(summary.c_str(), f);
    std::fclose(f);
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("peak RSS %.1f MiB; results in %s\n", static_cast<double>(usage.ru_maxrss) / 1024.0,
              FLAGS_output_dir.c_str());
  if (g_interrupted) std::printf("(interrupted: stopped before the end of the bag)\n");
  if (!run_status.ok()) return Fail(run_status);
  if (!closed.ok()) return Fail(closed);
  return 0;
}

}  // namespace
}  // namespace swarmlio::tools

int main(int argc, char** argv) {
  gflags::SetUsageMessage("one drone of the live swarm: real time, UDP (docs/online.md)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  return swarmlio::tools::Main();
}
