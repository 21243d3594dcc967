// Teammate detection + tracking time per scan (docs/teammate.md).
//
//   taskset -c 0 bench_teammate [--benchmark_filter=ProcessScan]
//
// The scans are uav1's (a Livox Mid-360, ~20k points per scan) in the
// indoor_3uav scenario (argument 0) and in the decoys scenario (argument 1:
// the same flight among retro-reflective decoys), prepared once by the simulation harness (true poses,
// motion-compensated) and kept in memory. BM_ProcessScan times
// TeammateDetector::ProcessScan alone, one scan per iteration, over the part of
// the flight where both teammates are identified and tracked (after
// kWarmupS); when the recording is exhausted a fresh detector replays the
// warm-up untimed. The counters give the median and 90th percentile per scan.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "sim_harness.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/teammate/point_removal.h"

namespace swarmlio::teammate {
namespace {

constexpr double kDurationS = 32.0;  // simulated flight
constexpr double kWarmupS = 24.0;    // both teammates identified by then (23.8 s)

struct Recording {
  std::vector<harness::PreparedScan> scans;
  size_t first_timed = 0;
};

Recording* MakeRecording(const std::string& scenario_name) {
    auto* r = new Recording;
    sim::Scenario scenario;
    const std::string path =
        std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/" + scenario_name + ".yaml";
    Status status = sim::LoadScenario(path, &scenario);
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.message().c_str());
      std::exit(1);
    }
    scenario.options.duration_s = kDurationS;
    const sim::Simulator sim(std::move(scenario.scene), scenario.drones, scenario.objects,
                             scenario.simulation_config());
    status = harness::SimulateObserver(sim, 0, harness::HarnessOptions(),
                                       [&](const harness::PreparedScan& scan) {
                                         r->scans.push_back(scan);
                                         return Status::Ok();
                                       });
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.message().c_str());
      std::exit(1);
    }
    while (r->first_timed < r->scans.size() && r->scans[r->first_timed].t_true_s < kWarmupS) {
      ++r->first_timed;
    }
    return r;
}

// 0: indoor_3uav, 1: decoys.
const Recording& GetRecording(int which = 0) {
  static const Recording* indoor = MakeRecording("indoor_3uav");
  if (which == 0) return *indoor;
  static const Recording* decoys = MakeRecording("decoys");
  return *decoys;
}

void Feed(TeammateDetector* detector, const harness::PreparedScan& scan, ScanResult* result) {
  for (const TeammateOdometry& m : scan.odometry) detector->AddTeammateOdometry(m);
  (void)detector->ProcessScan(scan.stamp_ns, scan.T_Gi_bi, scan.points, result);
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}

void BM_ProcessScan(benchmark::State& state) {
  const Recording& rec = GetRecording(static_cast<int>(state.range(0)));
  std::unique_ptr<TeammateDetector> detector;
  ScanResult result;
  size_t cursor = rec.scans.size();
  std::vector<double> times_ms;
  double points = 0.0, teammates_seen = 0.0;
  for (auto _ : state) {
    if (cursor >= rec.scans.size()) {
      detector = std::make_unique<TeammateDetector>(0, TeammateDetectorOptions());
      for (size_t k = 0; k < rec.first_timed; ++k) Feed(detector.get(), rec.scans[k], &result);
      cursor = rec.first_timed;
    }
    const harness::PreparedScan& scan = rec.scans[cursor++];
    for (const TeammateOdometry& m : scan.odometry) detector->AddTeammateOdometry(m);
    const auto start = std::chrono::steady_clock::now();
    const Status status = detector->ProcessScan(scan.stamp_ns, scan.T_Gi_bi, scan.points, &result);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    benchmark::DoNotOptimize(status.ok());
    state.SetIterationTime(seconds);
    times_ms.push_back(1e3 * seconds);
    points += static_cast<double>(scan.points.size());
    teammates_seen += static_cast<double>(result.observations.size());
  }
  const double n = static_cast<double>(times_ms.size());
  state.counters["median_ms"] = Quantile(times_ms, 0.5);
  state.counters["p90_ms"] = Quantile(times_ms, 0.9);
  state.counters["max_ms"] = times_ms.empty() ? 0.0 : *std::max_element(times_ms.begin(), times_ms.end());
  state.counters["points_per_scan"] = points / n;
  state.counters["teammates_seen_per_scan"] = teammates_seen / n;
  state.counters["identified"] = static_cast<double>(detector->IdentifiedTeammates().size());
}
BENCHMARK(BM_ProcessScan)
    ->Arg(0)
    ->Arg(1)
    ->ArgNames({"decoys"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(2000);

// The stages on their own, on the same scans.
void BM_ReflectiveClustering(benchmark::State& state) {
  const Recording& rec = GetRecording();
  ReflectiveClusterer clusterer{ClusteringOptions()};
  std::vector<PointCluster> clusters;
  size_t cursor = rec.first_timed;
  for (auto _ : state) {
    clusterer.FindReflectiveClusters(rec.scans[cursor].points, &clusters);
    benchmark::DoNotOptimize(clusters.data());
    if (++cursor >= rec.scans.size()) cursor = rec.first_timed;
  }
}
BENCHMARK(BM_ReflectiveClustering)->Unit(benchmark::kMicrosecond);

void BM_ClusterRegion(benchmark::State& state) {
  const Recording& rec = GetRecording();
  ReflectiveClusterer clusterer{ClusteringOptions()};
  PointCluster cluster;
  const harness::PreparedScan& scan = rec.scans[rec.first_timed];
  const Eigen::Vector3d center(2.0, 1.0, 0.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(clusterer.ClusterRegion(scan.points, center, 0.5, &cluster));
  }
}
BENCHMARK(BM_ClusterRegion)->Unit(benchmark::kMicrosecond);

void BM_FindPointsNear(benchmark::State& state) {
  const Recording& rec = GetRecording();
  const harness::PreparedScan& scan = rec.scans[rec.first_timed];
  const std::vector<Eigen::Vector3d> centers = {{2.0, 1.0, 0.0}, {-1.0, 2.0, 0.5}};
  std::vector<int> indices;
  for (auto _ : state) {
    FindPointsNear(scan.points, centers, 0.7, &indices);
    benchmark::DoNotOptimize(indices.data());
  }
}
BENCHMARK(BM_FindPointsNear)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace swarmlio::teammate

BENCHMARK_MAIN();
