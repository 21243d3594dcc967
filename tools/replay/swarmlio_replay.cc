// swarmlio_replay: runs the estimators of N drones on their recorded bags in
// one process (N = 1: single-drone LiDAR-inertial odometry), inter-drone
// messages through a seeded simulated network, and writes into --output_dir:
//   <name>_tum.txt     estimated trajectory (TUM: t x y z qx qy qz qw, body in G)
//   <name>_map.pcd     the final local map (G frame)
//   <name>_timing.csv  per-scan counts and stage times
//   metrics.{md,csv,json}  per-drone APE/RPE, time statistics, real-time factor, NEES
//   top_view.png, ape_over_time.png, network.csv
// and prints a summary and the metrics table (docs/replay.md).
//
//   swarmlio_replay --manifest=sim_out/swarm.yaml --output_dir=results/run1
//   swarmlio_replay --bags=a.bag --sensor_preset=configs/livox_avia.yaml --output_dir=out
#include <gflags/gflags.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "progress_bar.h"
#include "report.h"
#include "swarm_report.h"
#include "swarmlio/common/split_list.h"
#include "swarmlio/config/config_file.h"
#include "swarmlio/driver/manifest.h"
#include "swarmlio/eval/consistency.h"
#include "swarmlio/eval/error_statistics.h"
#include "swarmlio/net/swarm_key_file.h"
#include "swarmlio/replay/dropped_scans.h"
#include "swarmlio/replay/swarm_replay.h"

DEFINE_string(manifest, "", "swarm manifest YAML (docs/replay.md); or use --bags");
DEFINE_string(bags,
              "",
              "comma-separated logs, one per drone (instead of --manifest): ROS1 bags, MCAP "
              "files, rosbag2 .db3 files or folders");
DEFINE_string(names, "", "comma-separated drone names for --bags (default uav1, uav2, ...)");
DEFINE_string(sensor_preset, "", "sensor preset (configs/*.yaml) for every bag of --bags");
DEFINE_string(output_dir, "", "results folder (created)");
DEFINE_double(max_duration_s, 0.0, "replay only this much log time [s]; 0 = all");
DEFINE_bool(save_maps, true, "write <name>_map.pcd per drone");
DEFINE_bool(single_agent, false,
            "ablation: every drone runs alone (no messages), as single-agent odometry");
DEFINE_string(estimator, "",
              "back end of every drone: filter | window (docs/window.md); default: each "
              "drone's odometry.estimator");
DEFINE_int32(window_size, 0,
             "K (scan states) of the window back end for every drone; 0: each drone's "
             "odometry.window.size");
DEFINE_string(window_linear_solver, "",
              "linear solver of the window for every drone: dense_normal_cholesky | dense_qr | "
              "dense_schur | sparse_normal_cholesky; default: each drone's "
              "odometry.window.experimental.linear_solver");
DEFINE_string(window_reassociate, "",
              "all | newest: re-associate every scan of the window at each iteration, or only "
              "the newest (default: each drone's "
              "odometry.window.experimental.reassociate_all_scans)");
DEFINE_string(drone_overrides, "",
              "YAML file whose odometry:, imu:, lidar:, teammate: and swarm: sections apply over "
              "every drone's options from the manifest (a sweep variant, docs/sweeps.md); the "
              "odometry defaults that follow the LiDAR are not re-derived. The back-end flags "
              "above apply after it");
DEFINE_int64(network_seed, -1,
             "seed of the simulated network (over --network_config's); -1: the config's");
DEFINE_string(received_packets, "",
              "offline re-run of live drones (docs/online.md): name=<name>_received.bin,... "
              "those drones receive exactly the recorded datagrams at their recorded arrival "
              "times instead of the simulated network (needs --key_file); the scans listed in "
              "<name>_dropped_scans.txt next to it (the ones the live run dropped) are left out");
DEFINE_string(key_file, "",
              "the swarm key (64 hex digits) the recorded datagrams were authenticated with; "
              "default: the simulation key of the network seed");
DEFINE_string(network_config, "",
              "YAML file with a `network:` section (latency, jitter, loss, reordering, "
              "duplication, seed; docs/network.md); default: the NetworkOptions defaults");

namespace swarmlio::tools {
namespace {

// The live process writes <name>_dropped_scans.txt next to
// <name>_received.bin; a recording without it re-runs every scan.
Status ReadDroppedScansNextTo(const std::string& name, const std::string& received_path,
                              replay::ReplayOptions* options) {
  const std::string suffix = "_received.bin";
  if (received_path.size() < suffix.size() ||
      received_path.compare(received_path.size() - suffix.size(), suffix.size(), suffix) != 0) {
    std::fprintf(stderr, "note: %s: not a <name>_received.bin path, every scan is re-run\n",
                 received_path.c_str());
    return Status::Ok();
  }
  const std::string path =
      received_path.substr(0, received_path.size() - suffix.size()) + "_dropped_scans.txt";
  if (!std::filesystem::exists(path)) {
    std::fprintf(stderr, "note: no %s: every scan of %s is re-run\n", path.c_str(), name.c_str());
    return Status::Ok();
  }
  return replay::ReadDroppedScans(path, &options->dropped_scans[name]);
}

// --received_packets and --key_file into the replay options.
Status ApplyReceivedPacketFlags(replay::ReplayOptions* options) {
  for (const std::string& item : SplitList(FLAGS_received_packets)) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) {
      return Status::InvalidArgument("--received_packets: '" + item +
                                     "' is not name=path (e.g. uav1=out/uav1_received.bin)");
    }
    const std::string name = item.substr(0, eq), path = item.substr(eq + 1);
    options->received_packets[name] = path;
    SWARMLIO_RETURN_IF_ERROR(ReadDroppedScansNextTo(name, path, options));
  }
  if (!FLAGS_key_file.empty()) {
    net::SwarmKey key;
    SWARMLIO_RETURN_IF_ERROR(net::LoadSwarmKeyFile(FLAGS_key_file, &key).WithContext("--key_file"));
    options->key = key;
  } else if (!options->received_packets.empty()) {
    return Status::InvalidArgument(
        "--received_packets needs --key_file (the live swarm's key authenticates the datagrams)");
  }
  return Status::Ok();
}

// --drone_overrides: the file's sections over every drone's options.
Status ApplyDroneOverrides(driver::SwarmManifest* manifest) {
  if (FLAGS_drone_overrides.empty()) return Status::Ok();
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Load(FLAGS_drone_overrides, &file));
  for (driver::DroneInput& d : manifest->drones) {
    SWARMLIO_RETURN_IF_ERROR(file.Read("odometry", &d.odometry));
    SWARMLIO_RETURN_IF_ERROR(file.Read("imu", &d.imu));
    SWARMLIO_RETURN_IF_ERROR(file.Read("lidar", &d.lidar));
    SWARMLIO_RETURN_IF_ERROR(file.Read("teammate", &d.teammate));
    SWARMLIO_RETURN_IF_ERROR(file.Read("swarm", &d.swarm));
  }
  return file.CheckNoUnusedSections();
}

// The back-end flags, applied to every drone's odometry options.
Status ApplyEstimatorFlags(driver::SwarmManifest* manifest) {
  for (driver::DroneInput& d : manifest->drones) {
    lio::OdometryOptions& o = d.odometry;
    if (!FLAGS_estimator.empty() && !config::EnumFromString(FLAGS_estimator, &o.estimator)) {
      return Status::InvalidArgument("--estimator=" + FLAGS_estimator + ": expected one of " +
                                     config::EnumChoices<lio::EstimatorKind>());
    }
    if (FLAGS_window_size != 0) o.window.size = FLAGS_window_size;
    if (!FLAGS_window_linear_solver.empty() &&
        !config::EnumFromString(FLAGS_window_linear_solver, &o.window.linear_solver)) {
      return Status::InvalidArgument("--window_linear_solver=" + FLAGS_window_linear_solver +
                                     ": expected one of " +
                                     config::EnumChoices<lio::WindowLinearSolver>());
    }
    if (FLAGS_window_reassociate == "all" || FLAGS_window_reassociate == "newest") {
      o.window.reassociate_all_scans = FLAGS_window_reassociate == "all";
    } else if (!FLAGS_window_reassociate.empty()) {
      return Status::InvalidArgument("--window_reassociate=" + FLAGS_window_reassociate +
                                     ": expected all or newest");
    }
    if (const std::string invalid = o.Validate(); !invalid.empty()) {
      return Status::InvalidArgument(d.name + ": odometry." + invalid);
    }
  }
  return Status::Ok();
}

struct StageStats {
  const char* name;
  double lio::ScanTimings::*field;
};

void PrintSummary(const replay::DroneRunner& d, double wall_s) {
  const auto& scans = d.scans();
  std::vector<double> total;
  int64_t updated = 0;
  for (const swarm::DroneOutput& s : scans) {
    if (!s.ego.updated) continue;
    total.push_back(1e3 * s.ego.timings.total_s);
    ++updated;
  }
  const swarm::DroneEstimator& e = d.estimator();
  const lio::OdometryCounters& c = e.odometry_counters();
  std::printf("%s: %lld scans processed, %lld updated (%lld degenerate), %lld dropped before "
              "IMU init; map %zu points\n",
              d.input().name.c_str(), static_cast<long long>(c.scans_processed),
              static_cast<long long>(updated), static_cast<long long>(c.scans_degenerate),
              static_cast<long long>(c.scans_before_init), e.map_size());
  if (!e.initialized()) {
    std::printf("  IMU never initialized: %s\n", e.initialization_error().c_str());
  } else {
    std::printf("  IMU init: %s\n", e.initialization().Summary().c_str());
    std::printf("  odometry initialized at sensor stamp %lld ns\n",
                static_cast<long long>(e.initialization().stamp_ns));
    if (!e.initialization().sign_warning.empty()) {
      std::printf("  WARNING (IMU sign): %s\n",
                  e.initialization().sign_warning.c_str());
    }
  }
  if (!total.empty()) {
    std::printf("  per-scan time [ms]: median %.2f  p95 %.2f  max %.2f", eval::Percentile(total, 0.5),
                eval::Percentile(total, 0.95), eval::Percentile(total, 1.0));
    const StageStats stages[] = {{"preprocess", &lio::ScanTimings::preprocess_s},
                                 {"propagate", &lio::ScanTimings::propagate_s},
                                 {"undistort", &lio::ScanTimings::undistort_s},
                                 {"front end", &lio::ScanTimings::front_end_s},
                                 {"build", &lio::ScanTimings::build_s},
                                 {"marginalize", &lio::ScanTimings::marginalize_s},
                                 {"association", &lio::ScanTimings::association_s},
                                 {"solve", &lio::ScanTimings::solve_s},
                                 {"covariance", &lio::ScanTimings::covariance_s},
                                 {"map", &lio::ScanTimings::map_update_s}};
    const bool window = d.input().odometry.estimator == lio::EstimatorKind::kWindow;
    if (window) {
      std::printf("\n  window K = %d (%s), %lld restarts, %lld IMU re-integrations",
                  d.input().odometry.window.size,
                  config::EnumToString(d.input().odometry.window.linear_solver),
                  static_cast<long long>(c.window_restarts),
                  static_cast<long long>(c.window_reintegrations));
    }
    std::printf("\n  median per stage [ms]:");
    for (const StageStats& st : stages) {
      if (!window && (st.field == &lio::ScanTimings::build_s ||
                      st.field == &lio::ScanTimings::marginalize_s)) {
        continue;
      }
      std::vector<double> v;
      for (const swarm::DroneOutput& s : scans) {
        if (s.ego.updated) v.push_back(1e3 * (s.ego.timings.*st.field));
      }
      std::printf(" %s %.2f", st.name, eval::Percentile(v, 0.5));
    }
    std::printf("\n");
  }
  if (scans.size() >= 2) {
    const double log_s = ToSeconds(scans.back().ego.stamp_ns - scans.front().ego.stamp_ns);
    double busy_s = 0.0;
    for (const swarm::DroneOutput& s : scans) busy_s += s.ego.timings.total_s;
    std::printf("  log %.1f s, estimator busy %.2f s: %.1fx real time (whole replay %.1f s wall)\n",
                log_s, busy_s, busy_s > 0 ? log_s / busy_s : 0.0, wall_s);
  }
  if (!d.bag_ground_truth().empty()) {
    // NEES only when the ground truth is known to be in G (docs/replay.md).
    const eval::CovariantTrajectory estimate = replay::UpdatedEstimate(d.scans());
    const eval::Trajectory truth = eval::TrajectoryFromPoses(d.bag_ground_truth());
    eval::FrameCheck frame;
    eval::ConsistencyStats cs;
    eval::Trajectory aligned;
    Status status = eval::CheckGroundTruthFrame(estimate.poses, truth, d.input().ground_truth_frame,
                                                eval::FrameCheckOptions(), &frame);
    if (status.ok() && !frame.same_frame) {
      status = eval::AlignGroundTruthByFirstPose(estimate.poses, truth, frame, 0.05, &aligned);
    }
    if (status.ok()) {
      status = eval::EvaluateConsistency(estimate, frame.same_frame ? truth : aligned, 0.05, &cs);
    }
    if (status.ok()) {
      std::printf("  %s\n", frame.Summary().c_str());
      char nees[128];
      if (frame.same_frame && std::isfinite(cs.mean_position_nees_aligned)) {
        std::snprintf(nees, sizeof(nees),
                      "%.2f (expected %.0f; %.2f after the gauge alignment, %.3f deg)",
                      cs.mean_position_nees, cs.expected_position_nees,
                      cs.mean_position_nees_aligned, cs.gauge_rotation_deg);
      } else if (frame.same_frame) {
        std::snprintf(nees, sizeof(nees),
                      "%.2f (expected %.0f; no gauge alignment: the path fixes no rotation)",
                      cs.mean_position_nees, cs.expected_position_nees);
      } else {
        std::snprintf(nees, sizeof(nees), "n/a (frames differ)");
      }
      std::printf("  vs bag ground truth (%s), %d poses: position RMSE %.4f m (max %.4f), "
                  "rotation RMSE %.3f deg, mean position NEES %s\n",
                  frame.same_frame ? "same frame, no alignment" : "aligned by first pose",
                  cs.num_poses, cs.position_rmse_m, cs.position_max_m, cs.rotation_rmse_deg,
                  nees);
    } else {
      std::printf("  ground truth: %s\n", status.message().c_str());
    }
  }
  if (d.warnings().count > 0) {
    std::printf("  %lld warnings; first: %s\n", static_cast<long long>(d.warnings().count),
                d.warnings().first.c_str());
  }
  const io::ReadStats& rs = d.reader().stats();
  std::printf("  topics: imu %s, lidar %s, ground truth %s\n", d.reader().imu_topic().c_str(),
              d.reader().lidar_topic().c_str(),
              d.reader().ground_truth_topic().empty() ? "(none)"
                                                      : d.reader().ground_truth_topic().c_str());
  if (d.reader().lidar_message_type() == io::LidarMessageType::kPointCloud2) {
    std::printf("  point time: %s\n", rs.PointTimeSummary().c_str());
  }
  if (rs.recovery.recovered) std::printf("  damaged bag: %s\n", rs.recovery.Summary().c_str());
  if (rs.TotalSkipped() > 0) {
    std::printf("  bag reader skipped records:\n%s", rs.ToString().c_str());
  }
}

int Main() {
  if (FLAGS_output_dir.empty() || (FLAGS_manifest.empty() == FLAGS_bags.empty())) {
    std::fprintf(stderr,
                 "usage: swarmlio_replay (--manifest=FILE | --bags=A.bag[,B.bag...] "
                 "[--sensor_preset=FILE] [--names=a,b]) --output_dir=DIR\n");
    return 2;
  }
  driver::SwarmManifest manifest;
  Status status = FLAGS_manifest.empty()
                      ? driver::ManifestFromBags(SplitList(FLAGS_bags), FLAGS_sensor_preset,
                                                 SplitList(FLAGS_names), &manifest)
                      : driver::LoadManifest(FLAGS_manifest, &manifest);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  status = ApplyDroneOverrides(&manifest);
  if (status.ok()) status = ApplyEstimatorFlags(&manifest);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_output_dir, ec);
  if (ec) {
    std::fprintf(stderr, "error: %s: %s\n", FLAGS_output_dir.c_str(), ec.message().c_str());
    return 1;
  }
  std::unique_ptr<replay::SwarmReplay> run;
  status = replay::SwarmReplay::Create(manifest, &run);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  ProgressBar bar("replay " + manifest.name);
  replay::ReplayOptions options;
  options.max_duration_s = FLAGS_max_duration_s;
  options.single_agent = FLAGS_single_agent;
  if (!FLAGS_network_config.empty()) {
    config::ConfigFile file;
    status = config::ConfigFile::Load(FLAGS_network_config, &file);
    if (status.ok()) status = file.Read("network", &options.network);
    if (status.ok()) status = file.CheckNoUnusedSections();
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.message().c_str());
      return 1;
    }
  }
  if (FLAGS_network_seed >= 0) options.network.seed = FLAGS_network_seed;
  status = ApplyReceivedPacketFlags(&options);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  options.on_progress = [&](const replay::ReplayProgress& p) {
    std::ostringstream detail;
    detail << std::fixed << std::setprecision(1)
           << ToSeconds(p.stamp_ns - p.start_stamp_ns) << " s";
    bar.Update(p.Fraction(), detail.str());
  };
  const auto start = std::chrono::steady_clock::now();
  const Status run_status = run->Run(options);
  bar.Finish();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Results are written even after an error: partial results are kept.
  for (int i = 0; i < run->num_drones(); ++i) PrintSummary(run->drone(i), wall_s);
  {
    for (int i = 0; i < run->num_drones(); ++i) {
      const replay::DroneTraffic& t = run->traffic(i);
      std::printf("%s: sent %lld messages, received %lld (rejected %llu, duplicates %llu)\n",
                  run->drone(i).input().name.c_str(), static_cast<long long>(t.sent),
                  static_cast<long long>(t.received),
                  static_cast<unsigned long long>(t.channel.rejected),
                  static_cast<unsigned long long>(t.channel.duplicates));
      // Membership and fusion counters of the component (swarm::DroneEstimatorCounters).
      const swarm::DroneEstimatorCounters& c = run->drone(i).estimator().counters();
      std::printf("  messages ignored %lld, waiting for a clock offset %lld; teammates identified "
                  "%lld, removed %lld, restarted %lld; observations fused %lld active / %lld "
                  "passive / %lld gravity, rejected %lld\n",
                  static_cast<long long>(c.messages_ignored),
                  static_cast<long long>(c.messages_unsynchronized),
                  static_cast<long long>(c.identifications),
                  static_cast<long long>(c.teammates_removed),
                  static_cast<long long>(c.teammate_restarts),
                  static_cast<long long>(c.active_fused), static_cast<long long>(c.passive_fused),
                  static_cast<long long>(c.gravity_fused),
                  static_cast<long long>(c.observations_rejected));
      std::printf("%s", swarm::FormatBroadcastCounters(c, "  ").c_str());
      if (const net::ClockSync* sync = run->drone(i).estimator().clock_sync()) {
        const auto& scans = run->drone(i).scans();
        const int64_t now_ns = scans.empty() ? 0 : scans.back().ego.stamp_ns;
        std::vector<std::string> names;
        for (int j = 0; j < run->num_drones(); ++j) names.push_back(run->drone(j).input().name);
        std::printf("%s", net::FormatClockOffsets(*sync, now_ns, names, "  ").c_str());
      }
    }
  }
  ReportOptions report;
  report.output_dir = FLAGS_output_dir;
  report.single_agent = FLAGS_single_agent;
  report.save_maps = FLAGS_save_maps;
  std::string markdown, problems;
  const Status report_status = WriteReport(*run, report, &markdown, &problems);
  std::printf("\n%s%s\n", FLAGS_single_agent ? "single-agent ablation\n" : "", markdown.c_str());
  std::vector<PairMetrics> pairs;
  std::string swarm_markdown;
  const Status swarm_status =
      WriteSwarmReport(*run, FLAGS_output_dir, FLAGS_save_maps, &pairs, &swarm_markdown);
  if (run->num_drones() > 1) std::printf("teammates:\n%s\n", swarm_markdown.c_str());
  if (!swarm_status.ok()) problems += swarm_status.message() + "\n";
  int exit_code = run_status.ok() && report_status.ok() ? 0 : 1;
  if (!problems.empty()) std::fprintf(stderr, "errors:\n%s", problems.c_str());
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("peak RSS %.1f MiB, wall %.1f s; results in %s\n",
              static_cast<double>(usage.ru_maxrss) / 1024.0, wall_s, FLAGS_output_dir.c_str());
  if (!run_status.ok()) std::fprintf(stderr, "error: %s\n", run_status.message().c_str());
  return exit_code;
}

}  // namespace
}  // namespace swarmlio::tools

int main(int argc, char** argv) {
  gflags::SetUsageMessage("offline replay of one or more drones' bags (docs/replay.md)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  return swarmlio::tools::Main();
}
