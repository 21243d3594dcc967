// swarmlio_replay: runs the estimators of N drones on their recorded bags in
// one process (N = 1: single-drone LiDAR-inertial odometry) and writes, per
// drone, into --output_dir:
//   <name>_tum.txt     estimated trajectory (TUM: t x y z qx qy qz qw, body in G)
//   <name>_map.pcd     the final local map (G frame)
//   <name>_timing.csv  per-scan counts and stage times (docs/replay.md)
// and prints a summary (per-scan time statistics, real-time factor, peak RSS).
//
//   swarmlio_replay --manifest=sim_out/swarm.yaml --output_dir=results/run1
//   swarmlio_replay --bags=a.bag --sensor_preset=configs/livox_avia.yaml --output_dir=out
#include <gflags/gflags.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "progress_bar.h"
#include "swarmlio/io/pcd_writer.h"
#include "swarmlio/replay/consistency.h"
#include "swarmlio/replay/manifest.h"
#include "swarmlio/replay/swarm_replay.h"

DEFINE_string(manifest, "", "swarm manifest YAML (docs/replay.md); or use --bags");
DEFINE_string(bags, "", "comma-separated bags, one per drone (instead of --manifest)");
DEFINE_string(names, "", "comma-separated drone names for --bags (default uav1, uav2, ...)");
DEFINE_string(sensor_preset, "", "sensor preset (configs/*.yaml) for every bag of --bags");
DEFINE_string(output_dir, "", "results folder (created)");
DEFINE_double(max_duration_s, 0.0, "replay only this much log time [s]; 0 = all");
DEFINE_bool(save_maps, true, "write <name>_map.pcd per drone");

namespace swarmlio::tools {
namespace {

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

Status WriteTum(const std::string& path, const std::vector<replay::ScanRecord>& scans) {
  std::ofstream out(path);
  if (!out) return Status::IoError(path + ": cannot open for writing");
  out << "# timestamp tx ty tz qx qy qz qw (body/IMU frame in the drone's global frame G)\n";
  out << std::fixed;
  for (const replay::ScanRecord& s : scans) {
    const Eigen::Quaterniond& q = s.state.q_G_b;
    const Eigen::Vector3d& p = s.state.p_b_in_G;
    out << std::setprecision(9) << StampSeconds(s.stamp_ns) << std::setprecision(9) << " "
        << p.x() << " " << p.y() << " " << p.z() << " " << q.x() << " " << q.y() << " " << q.z()
        << " " << q.w() << "\n";
  }
  return out ? Status::Ok() : Status::IoError(path + ": write failed");
}

Status WriteTiming(const std::string& path, const std::vector<replay::ScanRecord>& scans) {
  std::ofstream out(path);
  if (!out) return Status::IoError(path + ": cannot open for writing");
  out << "stamp_s,updated,raw_points,points,correspondences,iterations,min_normal_information,"
         "degenerate,map_points,"
         "preprocess_ms,propagate_ms,undistort_ms,association_ms,solve_ms,covariance_ms,"
         "map_update_ms,total_ms\n";
  out << std::fixed;
  for (const replay::ScanRecord& s : scans) {
    const lio::ScanTimings& t = s.timings;
    out << std::setprecision(9) << StampSeconds(s.stamp_ns) << "," << (s.updated ? 1 : 0) << ","
        << s.num_raw_points << "," << s.num_points << "," << s.num_correspondences << ","
        << s.iterations << "," << std::setprecision(2) << s.min_normal_information << ","
        << (s.degenerate ? 1 : 0) << "," << s.map_size << std::setprecision(4) << ","
        << 1e3 * t.preprocess_s << "," << 1e3 * t.propagate_s << "," << 1e3 * t.undistort_s << ","
        << 1e3 * t.association_s << "," << 1e3 * t.solve_s << "," << 1e3 * t.covariance_s << ","
        << 1e3 * t.map_update_s << "," << 1e3 * t.total_s << "\n";
  }
  return out ? Status::Ok() : Status::IoError(path + ": write failed");
}

struct StageStats {
  const char* name;
  double lio::ScanTimings::*field;
};

void PrintSummary(const replay::DroneRunner& d, double wall_s) {
  const auto& scans = d.scans();
  std::vector<double> total;
  int64_t updated = 0;
  for (const auto& s : scans) {
    if (!s.updated) continue;
    total.push_back(1e3 * s.timings.total_s);
    ++updated;
  }
  const lio::OdometryCounters& c = d.odometry().counters();
  std::printf("%s: %lld scans processed, %lld updated (%lld degenerate), %lld dropped before "
              "IMU init; map %zu points\n",
              d.input().name.c_str(), static_cast<long long>(c.scans_processed),
              static_cast<long long>(updated), static_cast<long long>(c.scans_degenerate),
              static_cast<long long>(c.scans_before_init), d.odometry().map_size());
  if (!d.odometry().initialized()) {
    std::printf("  IMU never initialized: %s\n", d.odometry().initialization_error().c_str());
  } else {
    std::printf("  IMU init: %s\n", d.odometry().initialization().Summary().c_str());
  }
  if (!total.empty()) {
    std::printf("  per-scan time [ms]: median %.2f  p95 %.2f  max %.2f", Percentile(total, 0.5),
                Percentile(total, 0.95), Percentile(total, 1.0));
    const StageStats stages[] = {{"preprocess", &lio::ScanTimings::preprocess_s},
                                 {"propagate", &lio::ScanTimings::propagate_s},
                                 {"undistort", &lio::ScanTimings::undistort_s},
                                 {"association", &lio::ScanTimings::association_s},
                                 {"solve", &lio::ScanTimings::solve_s},
                                 {"covariance", &lio::ScanTimings::covariance_s},
                                 {"map", &lio::ScanTimings::map_update_s}};
    std::printf("\n  median per stage [ms]:");
    for (const StageStats& st : stages) {
      std::vector<double> v;
      for (const auto& s : scans) {
        if (s.updated) v.push_back(1e3 * (s.timings.*st.field));
      }
      std::printf(" %s %.2f", st.name, Percentile(v, 0.5));
    }
    std::printf("\n");
  }
  if (scans.size() >= 2) {
    const double log_s = StampSeconds(scans.back().stamp_ns - scans.front().stamp_ns);
    double busy_s = 0.0;
    for (const auto& s : scans) busy_s += s.timings.total_s;
    std::printf("  log %.1f s, estimator busy %.2f s: %.1fx real time (whole replay %.1f s wall)\n",
                log_s, busy_s, busy_s > 0 ? log_s / busy_s : 0.0, wall_s);
  }
  if (!d.bag_ground_truth().empty()) {
    replay::ConsistencyStats cs;
    const Status status = replay::EvaluateConsistency(d.scans(), d.bag_ground_truth(), 0.05, &cs);
    if (status.ok()) {
      std::printf("  vs bag ground truth (same frame, no alignment), %d poses: position RMSE "
                  "%.4f m (max %.4f), rotation RMSE %.3f deg, mean position NEES %.2f "
                  "(expected %.0f)\n",
                  cs.num_poses, cs.position_rmse_m, cs.position_max_m, cs.rotation_rmse_deg,
                  cs.mean_position_nees, cs.expected_position_nees);
    } else {
      std::printf("  ground truth: %s\n", status.message().c_str());
    }
  }
  if (d.warnings().count > 0) {
    std::printf("  %lld warnings; first: %s\n", static_cast<long long>(d.warnings().count),
                d.warnings().first.c_str());
  }
  const io::ReadStats& rs = d.reader().stats();
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
  replay::SwarmManifest manifest;
  Status status = FLAGS_manifest.empty()
                      ? replay::ManifestFromBags(Split(FLAGS_bags), FLAGS_sensor_preset,
                                                 Split(FLAGS_names), &manifest)
                      : replay::LoadManifest(FLAGS_manifest, &manifest);
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
  options.on_progress = [&](const replay::ReplayProgress& p) {
    std::ostringstream detail;
    detail << std::fixed << std::setprecision(1)
           << StampSeconds(p.stamp_ns - p.start_stamp_ns) << " s";
    bar.Update(p.Fraction(), detail.str());
  };
  const auto start = std::chrono::steady_clock::now();
  const Status run_status = run->Run(options);
  bar.Finish();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Results are written even after an error: partial results are kept.
  int exit_code = run_status.ok() ? 0 : 1;
  const std::filesystem::path dir(FLAGS_output_dir);
  for (int i = 0; i < run->num_drones(); ++i) {
    const replay::DroneRunner& d = run->drone(i);
    const std::string& name = d.input().name;
    std::vector<Status> writes = {WriteTum((dir / (name + "_tum.txt")).string(), d.scans()),
                                  WriteTiming((dir / (name + "_timing.csv")).string(), d.scans())};
    if (FLAGS_save_maps) {
      writes.push_back(io::WritePcd((dir / (name + "_map.pcd")).string(), d.odometry().MapPoints()));
    }
    for (const Status& w : writes) {
      if (!w.ok()) {
        std::fprintf(stderr, "error: %s\n", w.message().c_str());
        exit_code = 1;
      }
    }
    PrintSummary(d, wall_s);
  }
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
