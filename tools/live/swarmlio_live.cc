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
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "live_outputs.h"
#include "swarmlio/eval/error_statistics.h"
#include "swarmlio/live/live_drone.h"
#include "swarmlio/live/steady_clock.h"
#include "swarmlio/net/swarm_key_file.h"
#include "swarmlio/net/udp_transport.h"
#include "swarmlio/replay/manifest.h"

DEFINE_string(manifest, "", "swarm manifest YAML (docs/replay.md); with --drone");
DEFINE_string(drone, "", "the drone of --manifest this process runs (its name)");
DEFINE_string(bag, "", "instead of --manifest: the drone's bag");
DEFINE_string(sensor_preset, "", "with --bag: sensor preset (configs/*.yaml)");
DEFINE_int32(drone_id, 0, "with --bag: the drone's swarm id (its index in the swarm)");
DEFINE_string(name, "", "with --bag: the drone's name (default uav<drone_id + 1>)");
DEFINE_string(key_file, "", "required: the swarm's pre-shared key, 64 hex digits "
                            "(head -c 32 /dev/urandom | xxd -p -c 64)");
DEFINE_string(udp_mode, "multicast", "multicast | broadcast | unicast");
DEFINE_int32(port, 8821, "UDP port: the swarm's (multicast, broadcast) or this drone's (unicast)");
DEFINE_string(peers, "",
              "id=host:port,... every teammate (unicast; other modes: source ids only); id is "
              "the swarm id or a drone name of --manifest");
DEFINE_string(multicast_group, "239.255.88.21", "multicast group");
DEFINE_string(interface_address, "0.0.0.0",
              "multicast: interface to join and send on; unicast: address to bind");
DEFINE_string(broadcast_address, "255.255.255.255", "broadcast mode destination");
DEFINE_double(rate, 1.0, "playback speed (1 = real time)");
DEFINE_double(start_s, 0.0, "skip the log's first seconds (a drone joining late or restarting)");
DEFINE_string(initialization, "",
              "static | in_flight: overrides the drone's odometry.initialization (a drone "
              "joining late or restarting while flying: in_flight); empty: the manifest's");
DEFINE_double(start_at_unix_s, 0.0,
              "start the playback at this wall-clock time (UNIX seconds; 0: at once): processes "
              "started together play the same instant of their logs together");
DEFINE_double(max_scan_backlog_s, 0.3, "a scan taken later than this behind playback is dropped");
DEFINE_int32(max_queued_scans, 4, "scans waiting for the estimator at most; more are dropped");
DEFINE_double(network_poll_period_ms, 2.0, "UDP poll period [ms]");
DEFINE_bool(imu_odom, true, "write <name>_imu_odom.csv (the IMU-rate propagated state)");
DEFINE_string(output_dir, "", "results folder (created)");

namespace swarmlio::tools {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnSignal(int) { g_interrupted = true; }

std::vector<std::string> Split(const std::string& s, char separator) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, separator);) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

Status ParsePeers(const std::string& text, const replay::SwarmManifest& manifest,
                  std::vector<net::UdpPeer>* peers) {
  for (const std::string& item : Split(text, ',')) {
    const size_t eq = item.find('=');
    const size_t colon = item.rfind(':');
    if (eq == std::string::npos || colon == std::string::npos || colon < eq) {
      return Status::InvalidArgument("--peers: '" + item + "' is not id=host:port");
    }
    const std::string id_text = item.substr(0, eq);
    net::UdpPeer peer;
    peer.id = -1;
    for (size_t i = 0; i < manifest.drones.size(); ++i) {
      if (manifest.drones[i].name == id_text) peer.id = static_cast<int>(i);
    }
    try {
      if (peer.id < 0) peer.id = std::stoi(id_text);
      peer.port = std::stoi(item.substr(colon + 1));
    } catch (const std::exception&) {
      return Status::InvalidArgument("--peers: '" + item +
                                     "': id (number or drone name) or port unreadable");
    }
    peer.address = item.substr(eq + 1, colon - eq - 1);
    peers->push_back(peer);
  }
  return Status::Ok();
}

Status LoadDrone(replay::DroneInput* drone, int* drone_id, replay::SwarmManifest* manifest) {
  if (!FLAGS_manifest.empty()) {
    if (FLAGS_drone.empty()) return Status::InvalidArgument("--manifest needs --drone=<name>");
    SWARMLIO_RETURN_IF_ERROR(replay::LoadManifest(FLAGS_manifest, manifest));
    for (size_t i = 0; i < manifest->drones.size(); ++i) {
      if (manifest->drones[i].name == FLAGS_drone) {
        *drone = manifest->drones[i];
        *drone_id = static_cast<int>(i);
        return Status::Ok();
      }
    }
    return Status::NotFound("--drone=" + FLAGS_drone + ": not in " + FLAGS_manifest);
  }
  const std::string name =
      FLAGS_name.empty() ? "uav" + std::to_string(FLAGS_drone_id + 1) : FLAGS_name;
  SWARMLIO_RETURN_IF_ERROR(
      replay::ManifestFromBags({FLAGS_bag}, FLAGS_sensor_preset, {name}, manifest));
  *drone = manifest->drones[0];
  *drone_id = FLAGS_drone_id;
  return Status::Ok();
}

Status BuildUdpOptions(const replay::SwarmManifest& manifest, net::UdpOptions* udp) {
  if (!config::EnumFromString(FLAGS_udp_mode, &udp->mode)) {
    return Status::InvalidArgument("--udp_mode=" + FLAGS_udp_mode + ": expected one of " +
                                   config::EnumChoices<net::UdpMode>());
  }
  udp->port = FLAGS_port;
  udp->multicast_group = FLAGS_multicast_group;
  udp->interface_address = FLAGS_interface_address;
  udp->broadcast_address = FLAGS_broadcast_address;
  SWARMLIO_RETURN_IF_ERROR(ParsePeers(FLAGS_peers, manifest, &udp->peers));
  if (const std::string invalid = udp->Validate(); !invalid.empty()) {
    return Status::InvalidArgument("udp options (--udp_mode, --port, --peers, ...): " + invalid);
  }
  return Status::Ok();
}

std::string Summary(const std::string& name, const live::LiveStats& s,
                    const live::LiveDrone& drone, const LiveOutputs& outputs,
                    const net::UdpStats& udp) {
  std::vector<double> latency(outputs.latencies_ms().begin(), outputs.latencies_ms().end());
  const double played_s = StampSeconds(s.sensor_end_ns - s.sensor_start_ns);
  const double imu_span_s =
      StampSeconds(outputs.last_imu_pose_ns() - outputs.first_imu_pose_ns());
  char buffer[2048];
  std::snprintf(
      buffer, sizeof(buffer),
      "%s: played %.1f s of log in %.1f s (rate %.2f)\n"
      "  scans: %lld played, %lld processed, %lld dropped (%lld queue full, %lld backlog)\n"
      "  latency scan end -> odometry out [ms]: median %.2f  p95 %.2f  max %.2f\n"
      "  IMU-rate odometry: %lld poses (%.0f Hz)\n"
      "  messages: sent %lld (send errors %lld, outbox full %lld); received %llu, rejected %llu "
      "(last: %s), duplicates %llu, own %llu; delivered %lld, message queue full %lld\n"
      "  UDP: %llu datagrams / %llu B sent (%llu dropped by a full buffer), %llu / %llu B "
      "received; recorded %lld datagrams\n"
      "  input stalls %lld; estimator warnings %lld%s%s\n",
      name.c_str(), played_s, 1e-9 * static_cast<double>(s.clock_elapsed_ns),
      played_s > 0 ? played_s / (1e-9 * static_cast<double>(s.clock_elapsed_ns)) : 0.0,
      static_cast<long long>(s.scans_played), static_cast<long long>(s.scans_processed),
      static_cast<long long>(s.scans_dropped_queue + s.scans_dropped_backlog),
      static_cast<long long>(s.scans_dropped_queue), static_cast<long long>(s.scans_dropped_backlog),
      eval::Percentile(latency, 0.5), eval::Percentile(latency, 0.95),
      eval::Percentile(latency, 1.0), static_cast<long long>(s.imu_poses),
      imu_span_s > 0 ? static_cast<double>(s.imu_poses - 1) / imu_span_s : 0.0,
      static_cast<long long>(s.messages_sent), static_cast<long long>(s.send_errors),
      static_cast<long long>(s.outgoing_dropped_queue),
      static_cast<unsigned long long>(s.channel.received),
      static_cast<unsigned long long>(s.channel.rejected),
      s.channel.last_reject_reason.empty() ? "-" : s.channel.last_reject_reason.c_str(),
      static_cast<unsigned long long>(s.channel.duplicates),
      static_cast<unsigned long long>(s.channel.own_packets),
      static_cast<long long>(s.messages_delivered), static_cast<long long>(s.messages_dropped_queue),
      static_cast<unsigned long long>(udp.datagrams_sent),
      static_cast<unsigned long long>(udp.bytes_sent),
      static_cast<unsigned long long>(udp.send_dropped),
      static_cast<unsigned long long>(udp.datagrams_received),
      static_cast<unsigned long long>(udp.bytes_received),
      static_cast<long long>(s.datagrams_logged), static_cast<long long>(s.input_stalls),
      static_cast<long long>(s.estimator_warnings), s.first_warning.empty() ? "" : "; first: ",
      s.first_warning.c_str());
  std::string text = buffer;
  const swarm::DroneEstimatorCounters& c = drone.estimator().counters();
  std::snprintf(buffer, sizeof(buffer),
                "  swarm: %lld identifications, %lld active + %lld passive observations fused "
                "(%lld repeats), %lld gravity; teammates restarted %lld, removed %lld; states "
                "waiting for a clock offset %lld, ignored %lld\n",
                static_cast<long long>(c.identifications), static_cast<long long>(c.active_fused),
                static_cast<long long>(c.passive_fused), static_cast<long long>(c.passive_repeated),
                static_cast<long long>(c.gravity_fused), static_cast<long long>(c.teammate_restarts),
                static_cast<long long>(c.teammates_removed),
                static_cast<long long>(c.messages_unsynchronized),
                static_cast<long long>(c.messages_ignored));
  return text + buffer;
}

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
  replay::SwarmManifest manifest;
  replay::DroneInput drone;
  int drone_id = 0;
  Status status = LoadDrone(&drone, &drone_id, &manifest);
  if (!status.ok()) return Fail(status);
  if (!FLAGS_initialization.empty() &&
      !config::EnumFromString(FLAGS_initialization, &drone.odometry.initialization)) {
    return Fail(Status::InvalidArgument("--initialization: '" + FLAGS_initialization +
                                        "' is not static or in_flight"));
  }
  live::LiveSetup setup;
  status = net::LoadSwarmKeyFile(FLAGS_key_file, &setup.key);
  if (!status.ok()) return Fail(status.WithContext("--key_file"));
  net::UdpOptions udp_options;
  status = BuildUdpOptions(manifest, &udp_options);
  if (!status.ok()) return Fail(status);
  live::LiveOptions options;
  options.rate = FLAGS_rate;
  options.start_offset_s = FLAGS_start_s;
  options.max_scan_backlog_s = FLAGS_max_scan_backlog_s;
  options.max_queued_scans = FLAGS_max_queued_scans;
  options.network_poll_period_ms = FLAGS_network_poll_period_ms;
  options.imu_rate_odometry = true;  // counted always; the file is --imu_odom
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_output_dir, ec);
  if (ec) return Fail(Status::IoError(FLAGS_output_dir + ": " + ec.message()));

  std::unique_ptr<net::UdpTransport> udp;
  status = net::UdpTransport::Create(udp_options, drone_id, &udp);
  if (!status.ok()) return Fail(status);
  std::unique_ptr<LiveOutputs> outputs;
  std::vector<std::string> drone_names;
  for (const replay::DroneInput& d : manifest.drones) drone_names.push_back(d.name);
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
  std::string summary = Summary(drone.name, live->stats(), *live, *outputs, udp->stats());
  {
    const live::LiveStats& st = live->stats();
    char line[256];
    std::snprintf(line, sizeof(line),
                  "  playback: sensor stamp %lld ns at steady clock %lld ns, rate %.6g\n",
                  static_cast<long long>(st.sensor_start_ns),
                  static_cast<long long>(st.clock_start_ns), FLAGS_rate);
    summary += line;
    std::snprintf(line, sizeof(line), "  odometry initialized at sensor stamp %lld ns (its G)\n",
                  static_cast<long long>(live->estimator().odometry().initialization().stamp_ns));
    summary += line;
    if (const net::ClockSync* sync = live->estimator().clock_sync()) {
      summary += net::FormatClockOffsets(*sync, st.sensor_end_ns, drone_names, "  ");
    }
  }
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
