// Chooses the local-map structure: one cycle = 5-NN queries for every point
// of a 2,000-point scan, then insertion of that scan (the order of a LIO
// update), on realistic maps. Candidates:
//   HashGrid/<cell_cm>: swarmlio::lio::LocalMap (robin_map of search cells;
//               cell_cm 0 = the default, 4 x leaf).
//   KdDynamic:  nanoflann KDTreeSingleIndexDynamicAdaptor (log-structured
//               forest of static trees; lazy deletion).
//   KdRebuild:  nanoflann KDTreeSingleIndexAdaptor rebuilt after every insert.
// All use the same leaf-voxel hash for on-insert downsampling, so only the
// neighbour structure differs. Before timing, every candidate's k-NN distances
// are checked against the hash grid's (exact) answers.
//
// Run (Release, one core):
//   taskset -c 0 build-map/tools/bench/bench_local_map --benchmark_min_time=2
#include <Eigen/Geometry>
#include <benchmark/benchmark.h>
#include <nanoflann.hpp>
#include <tsl/robin_map.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/map_voxel_key.h"

namespace swarmlio::lio {
namespace {

constexpr int kScanPoints = 2000;
constexpr int kNeighbors = 5;
constexpr int kScanPool = 32;
constexpr double kScanNoiseRmsM = 0.1;  // 3-D RMS of the scan noise [m]

// ---------------------------------------------------------------- scenes ---

// A rectangle origin + u * a + v * b, u, v in [0, 1].
struct Quad {
  Eigen::Vector3d origin, a, b;
  double Area() const { return a.cross(b).norm(); }
};

void AddBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& size, bool with_bottom,
            std::vector<Quad>* quads) {
  const Eigen::Vector3d x(size.x(), 0, 0), y(0, size.y(), 0), z(0, 0, size.z());
  quads->push_back({lo, x, z});
  quads->push_back({lo + y, x, z});
  quads->push_back({lo, y, z});
  quads->push_back({lo + x, y, z});
  quads->push_back({lo + z, x, y});
  if (with_bottom) quads->push_back({lo, x, y});
}

struct Scene {
  std::string name;
  std::vector<Quad> quads;
  std::vector<double> cumulative_area;
  Eigen::Vector3d drone = Eigen::Vector3d::Zero();
  double sensor_range_m = 0.0;
  LocalMapOptions map_options;

  void Finish() {
    double total = 0.0;
    for (const Quad& q : quads) cumulative_area.push_back(total += q.Area());
  }
  Eigen::Vector3d Sample(std::mt19937& rng) const {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double pick = u(rng) * cumulative_area.back();
    const size_t i = std::lower_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
                     cumulative_area.begin();
    const Quad& q = quads[std::min(i, quads.size() - 1)];
    return q.origin + u(rng) * q.a + u(rng) * q.b;
  }
};

// 10 x 8 x 4 m room with furniture and two pillars; map leaf 0.1 m or 0.3 m.
Scene IndoorScene(double leaf_m) {
  Scene s;
  s.name = "indoor";
  AddBox({0, 0, 0}, {10, 8, 4}, true, &s.quads);
  AddBox({1, 1, 0}, {2, 1, 0.75}, false, &s.quads);      // table
  AddBox({6, 0.2, 0}, {2.5, 0.6, 2.0}, false, &s.quads);  // cabinet
  AddBox({4, 5, 0}, {1.5, 1.5, 1.0}, false, &s.quads);    // crate
  AddBox({7.5, 5.5, 0}, {0.4, 0.4, 4.0}, false, &s.quads);  // pillar
  AddBox({2.5, 6, 0}, {0.4, 0.4, 4.0}, false, &s.quads);    // pillar
  AddBox({0.2, 3.5, 0}, {0.6, 2.0, 1.2}, false, &s.quads);  // shelf
  s.drone = {5.0, 4.0, 1.5};
  s.sensor_range_m = 20.0;
  s.map_options.leaf_size_m = leaf_m;
  s.map_options.half_extent_m = 100.0;
  s.Finish();
  return s;
}

// 120 x 120 m ground with 36 buildings; map leaf 0.5 m.
Scene OutdoorScene() {
  Scene s;
  s.name = "outdoor";
  s.quads.push_back({{-60, -60, 0}, {120, 0, 0}, {0, 120, 0}});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> footprint(5.0, 15.0), height(4.0, 20.0);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      if ((i == 2 || i == 3) && (j == 2 || j == 3)) continue;  // open square around the drone
      AddBox({-60 + 20.0 * i + 2, -60 + 20.0 * j + 2, 0},
             {footprint(rng), footprint(rng), height(rng)}, false, &s.quads);
    }
  }
  s.drone = {0.0, 0.0, 3.0};
  s.sensor_range_m = 60.0;
  s.map_options.leaf_size_m = 0.5;
  s.map_options.half_extent_m = 100.0;
  s.Finish();
  return s;
}

// Dense surface samples (4 per leaf area) inserted through the map's rule.
std::vector<Eigen::Vector3d> MapSamples(const Scene& s) {
  std::mt19937 rng(1);
  const double leaf = s.map_options.leaf_size_m;
  const size_t count = static_cast<size_t>(4.0 * s.cumulative_area.back() / (leaf * leaf));
  std::vector<Eigen::Vector3d> points;
  points.reserve(count);
  for (size_t i = 0; i < count; ++i) points.push_back(s.Sample(rng));
  return points;
}

std::vector<std::vector<Eigen::Vector3d>> Scans(const Scene& s) {
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, kScanNoiseRmsM / std::sqrt(3.0));
  std::vector<std::vector<Eigen::Vector3d>> scans(kScanPool);
  for (auto& scan : scans) {
    while (static_cast<int>(scan.size()) < kScanPoints) {
      const Eigen::Vector3d p = s.Sample(rng);
      if ((p - s.drone).norm() > s.sensor_range_m) continue;
      scan.push_back(p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
  }
  return scans;
}

// ------------------------------------------------------- k-d tree maps ---

struct PointsAdaptor {
  const std::vector<Eigen::Vector3d>* points;
  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using Metric = nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>;
using StaticTree = nanoflann::KDTreeSingleIndexAdaptor<Metric, PointsAdaptor, 3, uint32_t>;
using DynamicTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<Metric, PointsAdaptor, 3, uint32_t>;

// Point vector + leaf-voxel hash (same rule as LocalMap) + a nanoflann index.
class KdTreeMap {
 public:
  KdTreeMap(const LocalMapOptions& options, bool dynamic)
      : options_(options), dynamic_(dynamic), inv_leaf_(1.0 / options.leaf_size_m) {
    Reindex();
  }

  int Insert(const std::vector<Eigen::Vector3d>& points) {
    const size_t first = points_.size();
    for (const Eigen::Vector3d& p : points) {
      if ((p - center_).cwiseAbs().maxCoeff() > options_.half_extent_m) continue;
      auto [leaf, inserted] = leaf_counts_.try_emplace(VoxelKeyOf(p, inv_leaf_), 0u);
      (void)inserted;
      if (leaf->second >= static_cast<uint32_t>(options_.max_points_per_leaf)) continue;
      ++leaf.value();
      points_.push_back(p);
      alive_.push_back(1);
    }
    const int added = static_cast<int>(points_.size() - first);
    if (dynamic_) {
      if (added > 0) {
        dynamic_tree_->addPoints(static_cast<uint32_t>(first),
                                 static_cast<uint32_t>(points_.size() - 1));
      }
    } else {
      static_tree_ = std::make_unique<StaticTree>(3, adaptor_);  // rebuild
    }
    live_ += static_cast<size_t>(added);
    return added;
  }

  // Lazy deletion + compaction when half of the stored points are dead.
  void UpdateCenter(const Eigen::Vector3d& center) {
    center_ = center;
    if ((center - last_prune_).cwiseAbs().maxCoeff() <= options_.prune_distance_m) return;
    last_prune_ = center;
    for (size_t i = 0; i < points_.size(); ++i) {
      if (!alive_[i] ||
          (points_[i] - center).cwiseAbs().maxCoeff() <= options_.half_extent_m) {
        continue;
      }
      alive_[i] = 0;
      --live_;
      auto leaf = leaf_counts_.find(VoxelKeyOf(points_[i], inv_leaf_));
      if (--leaf.value() == 0) leaf_counts_.erase(leaf);
      if (dynamic_) dynamic_tree_->removePoint(i);
    }
    if (2 * live_ < points_.size() || !dynamic_) {
      size_t j = 0;
      for (size_t i = 0; i < points_.size(); ++i) {
        if (alive_[i]) points_[j++] = points_[i];
      }
      points_.resize(j);
      alive_.assign(j, 1);
      Reindex();
    }
  }

  int KNearest(const Eigen::Vector3d& q, int k, uint32_t* indices, double* d2) const {
    nanoflann::KNNResultSet<double, uint32_t> result(static_cast<size_t>(k));
    result.init(indices, d2);
    if (dynamic_) {
      dynamic_tree_->findNeighbors(result, q.data(), nanoflann::SearchParams());
    } else {
      static_tree_->findNeighbors(result, q.data(), nanoflann::SearchParams());
    }
    return static_cast<int>(result.size());
  }

  size_t size() const { return live_; }
  size_t stored() const { return points_.size(); }

 private:
  void Reindex() {
    dynamic_tree_.reset();
    static_tree_.reset();
    if (dynamic_) {
      dynamic_tree_ = std::make_unique<DynamicTree>(3, adaptor_,
                                                    nanoflann::KDTreeSingleIndexAdaptorParams(10));
    } else {
      static_tree_ = std::make_unique<StaticTree>(3, adaptor_);
    }
  }

  LocalMapOptions options_;
  bool dynamic_;
  double inv_leaf_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<uint8_t> alive_;
  size_t live_ = 0;
  PointsAdaptor adaptor_{&points_};
  tsl::robin_map<VoxelKey, uint32_t, VoxelKeyHash> leaf_counts_;
  std::unique_ptr<StaticTree> static_tree_;
  std::unique_ptr<DynamicTree> dynamic_tree_;
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_prune_ = Eigen::Vector3d::Zero();
};

// ------------------------------------------------------------- fixtures ---

enum Candidate { kHashGrid = 0, kKdDynamic = 1, kKdRebuild = 2 };

struct Setup {
  Scene scene;
  std::vector<Eigen::Vector3d> samples;
  std::vector<std::vector<Eigen::Vector3d>> scans;
};

const Setup& GetSetup(int scene_id) {
  static const Setup* setups[3] = {nullptr, nullptr, nullptr};
  if (setups[scene_id] == nullptr) {
    auto* s = new Setup;
    s->scene = scene_id == 0 ? IndoorScene(0.1) : scene_id == 1 ? IndoorScene(0.3) : OutdoorScene();
    s->samples = MapSamples(s->scene);
    s->scans = Scans(s->scene);
    setups[scene_id] = s;
  }
  return *setups[scene_id];
}

const char* SceneLabel(int scene_id) {
  return scene_id == 0 ? "indoor_leaf0.1" : scene_id == 1 ? "indoor_leaf0.3" : "outdoor_leaf0.5";
}

// Checks the k-d tree's 5-NN distances against the exact hash grid.
void CrossCheck(const LocalMap& grid, const KdTreeMap& tree,
                const std::vector<Eigen::Vector3d>& queries) {
  std::vector<Neighbor> nn;
  uint32_t idx[kNeighbors];
  double d2[kNeighbors];
  for (const auto& q : queries) {
    const int n = grid.KNearest(q, kNeighbors, &nn);
    const int m = tree.KNearest(q, kNeighbors, idx, d2);
    const double r2 = grid.options().max_search_radius_m * grid.options().max_search_radius_m;
    int m_in = 0;
    while (m_in < m && d2[m_in] <= r2) ++m_in;
    bool ok = n == m_in;
    for (int i = 0; ok && i < n; ++i) ok = std::abs(nn[i].squared_distance_m2 - d2[i]) < 1e-9;
    if (!ok) {
      std::fprintf(stderr, "k-NN mismatch between the hash grid and the k-d tree\n");
      std::abort();
    }
  }
}

void BM_InsertAndKnn(benchmark::State& state) {
  const int scene_id = static_cast<int>(state.range(0));
  const auto candidate = static_cast<Candidate>(state.range(1));
  const Setup& setup = GetSetup(scene_id);
  LocalMapOptions options = setup.scene.map_options;
  if (candidate == kHashGrid) options.cell_size_m = 0.01 * static_cast<double>(state.range(2));

  LocalMap grid(options);
  std::unique_ptr<KdTreeMap> tree;
  grid.UpdateCenter(setup.scene.drone);
  grid.Insert(setup.samples);
  for (const auto& scan : setup.scans) grid.Insert(scan);  // warm up to steady state
  if (candidate != kHashGrid) {
    tree = std::make_unique<KdTreeMap>(options, candidate == kKdDynamic);
    tree->UpdateCenter(setup.scene.drone);
    tree->Insert(setup.samples);
    for (const auto& scan : setup.scans) tree->Insert(scan);
    CrossCheck(grid, *tree, setup.scans[0]);
  }

  std::vector<Neighbor> nn;
  uint32_t idx[kNeighbors];
  double d2[kNeighbors];
  size_t cycle = 0;
  int64_t found = 0;
  for (auto _ : state) {
    const std::vector<Eigen::Vector3d>& scan = setup.scans[cycle++ % setup.scans.size()];
    if (candidate == kHashGrid) {
      for (const auto& q : scan) found += grid.KNearest(q, kNeighbors, &nn);
      grid.Insert(scan);
    } else {
      for (const auto& q : scan) found += tree->KNearest(q, kNeighbors, idx, d2);
      tree->Insert(scan);
    }
    benchmark::DoNotOptimize(found);
  }
  state.counters["map_points"] =
      static_cast<double>(candidate == kHashGrid ? grid.size() : tree->size());
  if (candidate == kHashGrid) {
    state.counters["cells"] = static_cast<double>(grid.num_cells());
    state.counters["map_MiB"] = static_cast<double>(grid.MemoryBytes()) / (1 << 20);
  }
  state.SetLabel(SceneLabel(scene_id));
}

void InsertAndKnnArgs(benchmark::internal::Benchmark* b) {
  for (int scene = 0; scene < 3; ++scene) {
    for (int cell_cm : {0, 50, 100, 200}) b->Args({scene, kHashGrid, cell_cm});  // 0 = auto
    b->Args({scene, kKdDynamic, 0});
    b->Args({scene, kKdRebuild, 0});
  }
}
BENCHMARK(BM_InsertAndKnn)
    ->Apply(InsertAndKnnArgs)
    ->ArgNames({"scene", "candidate", "cell_cm"})
    ->Unit(benchmark::kMillisecond);

// Procedural endless outdoor world: ground z = 0 and 1 x 1 x 8 m pillars on
// a 10 m lattice (present where a hash of the lattice cell says so).
bool PillarAt(int64_t i, int64_t j) {
  uint64_t h = static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ULL ^
               static_cast<uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL;
  h ^= h >> 29;
  return (h & 3) == 0;
}

std::vector<Eigen::Vector3d> ProceduralScan(const Eigen::Vector3d& drone, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<Eigen::Vector3d> scan;
  constexpr double kRange = 40.0;
  while (static_cast<int>(scan.size()) < kScanPoints) {
    const double x = drone.x() + kRange * u(rng);
    const double y = drone.y() + kRange * u(rng);
    if (scan.size() % 2 == 0) {  // ground
      scan.emplace_back(x, y, noise(rng));
      continue;
    }
    const int64_t i = static_cast<int64_t>(std::floor(x / 10.0));
    const int64_t j = static_cast<int64_t>(std::floor(y / 10.0));
    if (!PillarAt(i, j)) continue;
    const double face = 0.5 * (u(rng) + 1.0);  // a pillar face at x = 10 i
    scan.emplace_back(10.0 * i + noise(rng), 10.0 * j + face, 4.0 * (u(rng) + 1.0));
  }
  return scan;
}

// 10,000 insert cycles along a 10 km straight-and-zigzag flight: the map
// size must plateau. Reports the largest and the final size.
void BM_BoundedLongRun(benchmark::State& state) {
  const auto candidate = static_cast<Candidate>(state.range(0));
  const int cycles = static_cast<int>(state.range(1));
  LocalMapOptions options;
  options.leaf_size_m = 0.5;
  options.half_extent_m = 50.0;
  options.prune_distance_m = 5.0;
  size_t max_points = 0, final_points = 0, max_stored = 0, max_bytes = 0;
  for (auto _ : state) {
    LocalMap grid(options);
    KdTreeMap tree(options, true);
    std::mt19937 rng(9);
    std::vector<Neighbor> nn;
    for (int c = 0; c < cycles; ++c) {
      const Eigen::Vector3d drone(1.0 * c, 30.0 * std::sin(0.01 * c), 3.0);
      const std::vector<Eigen::Vector3d> scan = ProceduralScan(drone, rng);
      if (candidate == kHashGrid) {
        grid.UpdateCenter(drone);
        grid.Insert(scan);
        max_points = std::max(max_points, grid.size());
        if (c % 100 == 0) max_bytes = std::max(max_bytes, grid.MemoryBytes());
        final_points = grid.size();
      } else {
        tree.UpdateCenter(drone);
        tree.Insert(scan);
        max_points = std::max(max_points, tree.size());
        max_stored = std::max(max_stored, tree.stored());
        final_points = tree.size();
      }
    }
  }
  state.counters["max_points"] = static_cast<double>(max_points);
  state.counters["final_points"] = static_cast<double>(final_points);
  if (candidate == kHashGrid) {
    state.counters["max_MiB"] = static_cast<double>(max_bytes) / (1 << 20);
  } else {
    state.counters["max_stored"] = static_cast<double>(max_stored);
  }
}
BENCHMARK(BM_BoundedLongRun)
    ->Args({kHashGrid, 10000})
    ->Args({kKdDynamic, 10000})
    ->ArgNames({"candidate", "cycles"})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace
}  // namespace swarmlio::lio

BENCHMARK_MAIN();
