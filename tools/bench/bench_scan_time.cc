// bench_scan_time: per-scan time of the odometry, per stage, for 1 and N
// threads (odometry.experimental.threads), on recorded logs of each sensor. Every drone of
// a swarm manifest is replayed as the single-agent ablation (no messages),
// through the same driver as swarmlio_replay, so the figures are the ones
// its <name>_timing.csv reports; each thread count replays the logs
// --repeats times and keeps, per scan, the fastest pass. The trajectories
// of every thread count are compared with the first one's (bit for bit).
//
//   bench_scan_time --manifest sim/swarm.yaml --threads 1,2 --repeats 3
//
// Run it pinned (taskset -c 0 for one thread, -c 0,1 for two) on an idle
// machine; docs/lio.md "Threads" has the figures of this machine.
#include <gflags/gflags.h>

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/split_list.h"
#include "swarmlio/driver/manifest.h"
#include "swarmlio/eval/error_statistics.h"
#include "swarmlio/replay/swarm_replay.h"

DEFINE_string(manifest, "", "swarm manifest (swarm.yaml of swarmlio_sim, or your own)");
DEFINE_string(threads, "1,2", "comma-separated odometry.experimental.threads values");
DEFINE_int32(repeats, 3, "passes per thread count (the fastest time per scan is kept)");

namespace {

using swarmlio::Status;

// One stage's time of every updated scan of one drone [ms].
struct Stage {
  const char* name;
  double swarmlio::lio::ScanTimings::*field;
};
constexpr Stage kStages[] = {
    {"preprocess", &swarmlio::lio::ScanTimings::preprocess_s},
    {"propagate", &swarmlio::lio::ScanTimings::propagate_s},
    {"undistort", &swarmlio::lio::ScanTimings::undistort_s},
    {"association", &swarmlio::lio::ScanTimings::association_s},
    {"solve", &swarmlio::lio::ScanTimings::solve_s},
    {"covariance", &swarmlio::lio::ScanTimings::covariance_s},
    {"front_end", &swarmlio::lio::ScanTimings::front_end_s},
    {"map_update", &swarmlio::lio::ScanTimings::map_update_s},
    {"total", &swarmlio::lio::ScanTimings::total_s},
};
constexpr int kNumStages = sizeof(kStages) / sizeof(kStages[0]);

const char* SensorName(swarmlio::LidarType type) {
  for (const auto& [value, name] : swarmlio::config::EnumTraits<swarmlio::LidarType>::kNames) {
    if (value == type) return name;
  }
  return "?";
}

// Per drone, per updated scan, the ScanOutput of one pass.
using Pass = std::vector<std::vector<swarmlio::lio::ScanOutput>>;

Status ReplayOnce(const swarmlio::driver::SwarmManifest& manifest, int threads, Pass* pass) {
  swarmlio::driver::SwarmManifest m = manifest;
  for (swarmlio::driver::DroneInput& d : m.drones) d.odometry.threads = threads;
  std::unique_ptr<swarmlio::replay::SwarmReplay> replay;
  SWARMLIO_RETURN_IF_ERROR(swarmlio::replay::SwarmReplay::Create(m, &replay));
  swarmlio::replay::ReplayOptions options;
  options.single_agent = true;
  SWARMLIO_RETURN_IF_ERROR(replay->Run(options));
  pass->assign(static_cast<size_t>(replay->num_drones()), {});
  for (int i = 0; i < replay->num_drones(); ++i) {
    for (const swarmlio::swarm::DroneOutput& s : replay->drone(i).scans()) {
      if (s.ego.updated) (*pass)[static_cast<size_t>(i)].push_back(s.ego);
    }
  }
  return Status::Ok();
}

bool SameTrajectory(const Pass& a, const Pass& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].size() != b[i].size()) return false;
    for (size_t k = 0; k < a[i].size(); ++k) {
      if (a[i][k].state.p_b_in_G != b[i][k].state.p_b_in_G ||
          a[i][k].state.q_G_b.coeffs() != b[i][k].state.q_G_b.coeffs()) {
        return false;
      }
    }
  }
  return true;
}

void PrintTable(const swarmlio::driver::SwarmManifest& manifest, int threads, const Pass& best) {
  for (size_t i = 0; i < best.size(); ++i) {
    std::printf("| %s | %s | %d |", manifest.drones[i].name.c_str(),
                SensorName(manifest.drones[i].lidar.type), threads);
    for (const Stage& stage : kStages) {
      std::vector<double> ms;
      for (const swarmlio::lio::ScanOutput& s : best[i]) ms.push_back(1e3 * (s.timings.*stage.field));
      std::printf(" %.3f / %.3f |", swarmlio::eval::Percentile(ms, 0.5),
                  swarmlio::eval::Percentile(ms, 0.95));
    }
    std::printf(" %zu |\n", best[i].size());
  }
}

// The fastest pass per scan and stage: `best` keeps, per scan, the timings
// of the pass whose total was smallest.
void KeepFastest(const Pass& pass, Pass* best) {
  if (best->empty()) {
    *best = pass;
    return;
  }
  for (size_t i = 0; i < pass.size(); ++i) {
    for (size_t k = 0; k < pass[i].size() && k < (*best)[i].size(); ++k) {
      if (pass[i][k].timings.total_s < (*best)[i][k].timings.total_s) {
        (*best)[i][k].timings = pass[i][k].timings;
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage("bench_scan_time --manifest swarm.yaml [--threads 1,2] [--repeats 3]");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  std::vector<int> threads;
  bool valid = true;
  for (const std::string& item : swarmlio::SplitList(FLAGS_threads)) {
    char* end = nullptr;
    const long value = std::strtol(item.c_str(), &end, 10);
    valid &= *end == '\0' && value >= 1 && value <= 256;
    threads.push_back(static_cast<int>(value));
  }
  if (FLAGS_manifest.empty() || threads.empty() || !valid || FLAGS_repeats < 1) {
    std::fprintf(stderr, "usage: %s\n", gflags::ProgramUsage());
    return 2;
  }
  swarmlio::driver::SwarmManifest manifest;
  if (const Status s = swarmlio::driver::LoadManifest(FLAGS_manifest, &manifest); !s.ok()) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    return 1;
  }
  std::printf("| drone | sensor | threads |");
  for (const Stage& stage : kStages) std::printf(" %s median / p95 [ms] |", stage.name);
  std::printf(" updated scans |\n|---|---|---:|");
  for (int k = 0; k < kNumStages; ++k) std::printf("---:|");
  std::printf("---:|\n");
  Pass reference;
  bool identical = true;
  for (const int t : threads) {
    Pass best;
    for (int r = 0; r < FLAGS_repeats; ++r) {
      Pass pass;
      if (const Status s = ReplayOnce(manifest, t, &pass); !s.ok()) {
        std::fprintf(stderr, "error: %s\n", s.message().c_str());
        return 1;
      }
      if (reference.empty()) reference = pass;
      identical &= SameTrajectory(reference, pass);
      KeepFastest(pass, &best);
    }
    PrintTable(manifest, t, best);
  }
  std::printf("\ntrajectories of every thread count and pass: %s\n",
              identical ? "bit-identical" : "DIFFERENT");
  return identical ? 0 : 1;
}
