#include "swarmlio/lio/local_map.h"

#include <tsl/robin_map.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <utility>

#include "swarmlio/common/check.h"
#include "swarmlio/lio/map_voxel_key.h"

namespace swarmlio::lio {
namespace {

struct Cell {
  std::vector<Eigen::Vector3d> points_in_G;
  std::vector<float> observed_ranges_m;  // parallel to points_in_G (0 = unknown)
};

// Squared distance from `q` to the cell box [lo, lo + size) on each axis.
inline double BoxSquaredDistance(const Eigen::Vector3d& q, const Eigen::Vector3d& lo,
                                 double size) {
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double below = lo[a] - q[a];
    const double above = q[a] - (lo[a] + size);
    const double d = std::max(0.0, std::max(below, above));
    d2 += d * d;
  }
  return d2;
}

// Inserts (p, d2) into `out`, kept sorted ascending and at most k long.
inline void PushCandidate(const Eigen::Vector3d& p, double d2, float range, int k,
                          std::vector<Neighbor>* out) {
  const int n = static_cast<int>(out->size());
  if (n == k && d2 >= (*out)[n - 1].squared_distance_m2) return;
  if (n < k) out->emplace_back();
  int i = static_cast<int>(out->size()) - 1;
  while (i > 0 && (*out)[i - 1].squared_distance_m2 > d2) {
    (*out)[i] = (*out)[i - 1];
    --i;
  }
  (*out)[i].point_in_G = p;
  (*out)[i].squared_distance_m2 = d2;
  (*out)[i].observed_range_m = range;
}

// The 26 neighbours of a cell ordered by how many axes they are offset on.
struct RingOne {
  int32_t offsets[26][3];
  RingOne() {
    int n = 0;
    for (int axes = 1; axes <= 3; ++axes) {
      for (int32_t dx = -1; dx <= 1; ++dx) {
        for (int32_t dy = -1; dy <= 1; ++dy) {
          for (int32_t dz = -1; dz <= 1; ++dz) {
            if (std::abs(dx) + std::abs(dy) + std::abs(dz) != axes) continue;
            offsets[n][0] = dx;
            offsets[n][1] = dy;
            offsets[n][2] = dz;
            ++n;
          }
        }
      }
    }
  }
  const int32_t (*begin() const)[3] { return offsets; }
  const int32_t (*end() const)[3] { return offsets + 26; }
};
const RingOne kRingOne;

}  // namespace

struct LocalMap::Impl {
  tsl::robin_map<VoxelKey, Cell, VoxelKeyHash> cells;
  tsl::robin_map<VoxelKey, uint32_t, VoxelKeyHash> leaf_counts;
  size_t num_points = 0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_prune_center = Eigen::Vector3d::Zero();
  double cell_size = 1.0;  // [m]
  double inv_cell = 1.0;
  double inv_leaf = 1.0;
};

std::string LocalMapOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  std::ostringstream os;
  const double cell = EffectiveCellSize();
  if (!(half_extent_m >= cell)) {
    os << "half_extent_m: must be at least the cell size (" << half_extent_m << " < " << cell
       << ")";
  } else if (!(max_search_radius_m <= 64.0 * cell)) {
    os << "max_search_radius_m: at most 64 cells (" << max_search_radius_m << " > 64 * " << cell
       << ")";
  }
  return os.str();
}

LocalMap::LocalMap(const LocalMapOptions& options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  const std::string error = options_.Validate();
  CHECK(error.empty()) << "LocalMapOptions: " << error;
  impl_->cell_size = options_.EffectiveCellSize();
  impl_->inv_cell = 1.0 / impl_->cell_size;
  impl_->inv_leaf = 1.0 / options_.leaf_size_m;
}

LocalMap::~LocalMap() = default;
LocalMap::LocalMap(LocalMap&&) noexcept = default;
LocalMap& LocalMap::operator=(LocalMap&&) noexcept = default;

bool LocalMap::Insert(const Eigen::Vector3d& point_in_G, double observed_range_m) {
  Impl& m = *impl_;
  if (!point_in_G.allFinite()) return false;
  if ((point_in_G - m.center).cwiseAbs().maxCoeff() > options_.half_extent_m) return false;
  auto [leaf, inserted] = m.leaf_counts.try_emplace(VoxelKeyOf(point_in_G, m.inv_leaf), 0u);
  (void)inserted;
  const bool known = std::isfinite(observed_range_m) && observed_range_m > 0.0;
  if (leaf->second >= static_cast<uint32_t>(options_.max_points_per_leaf)) {
    // Full leaf: a point seen from much closer replaces the leaf's point seen
    // from farthest (its angular noise is range x angle).
    if (!(options_.replace_range_ratio > 0.0) || !known) return false;
    auto it = m.cells.find(VoxelKeyOf(point_in_G, m.inv_cell));
    if (it == m.cells.end()) return false;
    Cell& cell = it.value();
    const VoxelKey leaf_key = leaf->first;
    int worst = -1;
    float worst_range = 0.0f;
    for (size_t i = 0; i < cell.points_in_G.size(); ++i) {
      const float r = cell.observed_ranges_m[i];
      if (r > worst_range && VoxelKeyOf(cell.points_in_G[i], m.inv_leaf) == leaf_key) {
        worst = static_cast<int>(i);
        worst_range = r;
      }
    }
    if (worst < 0 || !(observed_range_m < options_.replace_range_ratio * worst_range)) return false;
    cell.points_in_G[static_cast<size_t>(worst)] = point_in_G;
    cell.observed_ranges_m[static_cast<size_t>(worst)] = static_cast<float>(observed_range_m);
    return true;
  }
  ++leaf.value();
  Cell& cell = m.cells[VoxelKeyOf(point_in_G, m.inv_cell)];
  cell.points_in_G.push_back(point_in_G);
  cell.observed_ranges_m.push_back(known ? static_cast<float>(observed_range_m) : 0.0f);
  ++m.num_points;
  return true;
}

int LocalMap::Insert(const std::vector<Eigen::Vector3d>& points_in_G,
                     const std::vector<double>* observed_ranges_m) {
  CHECK(observed_ranges_m == nullptr || observed_ranges_m->size() == points_in_G.size());
  int added = 0;
  for (size_t i = 0; i < points_in_G.size(); ++i) {
    const double range = observed_ranges_m == nullptr ? 0.0 : (*observed_ranges_m)[i];
    added += Insert(points_in_G[i], range) ? 1 : 0;
  }
  return added;
}

int LocalMap::UpdateCenter(const Eigen::Vector3d& p_b_in_G) {
  impl_->center = p_b_in_G;
  if ((p_b_in_G - impl_->last_prune_center).cwiseAbs().maxCoeff() <= options_.prune_distance_m) {
    return 0;
  }
  return RemoveOutside(p_b_in_G);
}

int LocalMap::RemoveOutside(const Eigen::Vector3d& p_b_in_G) {
  Impl& m = *impl_;
  m.center = p_b_in_G;
  m.last_prune_center = p_b_in_G;
  std::vector<VoxelKey> doomed;
  for (const auto& [key, cell] : m.cells) {
    const Eigen::Vector3d c = VoxelCenter(key, m.cell_size);
    if ((c - p_b_in_G).cwiseAbs().maxCoeff() > options_.half_extent_m) doomed.push_back(key);
  }
  int removed = 0;
  for (const VoxelKey& key : doomed) {
    auto it = m.cells.find(key);
    for (const Eigen::Vector3d& p : it->second.points_in_G) {
      auto leaf = m.leaf_counts.find(VoxelKeyOf(p, m.inv_leaf));
      DCHECK(leaf != m.leaf_counts.end());
      if (--leaf.value() == 0) m.leaf_counts.erase(leaf);
    }
    removed += static_cast<int>(it->second.points_in_G.size());
    m.cells.erase(it);
  }
  m.num_points -= static_cast<size_t>(removed);
  return removed;
}

int LocalMap::KNearest(const Eigen::Vector3d& q_in_G, int k, std::vector<Neighbor>* out) const {
  CHECK(out != nullptr);
  out->clear();
  if (k <= 0 || !q_in_G.allFinite() || impl_->num_points == 0) return 0;
  const Impl& m = *impl_;
  const double size = m.cell_size;
  const double radius = options_.max_search_radius_m;
  const double radius2 = radius * radius;
  const VoxelKey c = VoxelKeyOf(q_in_G, m.inv_cell);
  auto visit = [&](int32_t dx, int32_t dy, int32_t dz) {
    const VoxelKey key{c.x + dx, c.y + dy, c.z + dz};
    const Eigen::Vector3d lo(key.x * size, key.y * size, key.z * size);
    const double box2 = BoxSquaredDistance(q_in_G, lo, size);
    if (box2 > radius2) return;
    if (static_cast<int>(out->size()) == k && box2 >= out->back().squared_distance_m2) return;
    const auto it = m.cells.find(key);
    if (it == m.cells.end()) return;
    const Cell& cell = it->second;
    for (size_t i = 0; i < cell.points_in_G.size(); ++i) {
      const double d2 = (cell.points_in_G[i] - q_in_G).squaredNorm();
      if (d2 <= radius2) PushCandidate(cell.points_in_G[i], d2, cell.observed_ranges_m[i], k, out);
    }
  };
  for (int32_t r = 0;; ++r) {
    if (r == 0) {
      visit(0, 0, 0);
    } else if (r == 1) {
      // Faces, then edges, then corners: the nearer cells fill the k results
      // first, so the box test skips more of the farther ones.
      for (const auto& o : kRingOne) visit(o[0], o[1], o[2]);
    } else {
      for (int32_t dx = -r; dx <= r; ++dx) {
        for (int32_t dy = -r; dy <= r; ++dy) {
          if (std::abs(dx) == r || std::abs(dy) == r) {
            for (int32_t dz = -r; dz <= r; ++dz) visit(dx, dy, dz);
          } else {
            visit(dx, dy, -r);
            visit(dx, dy, r);
          }
        }
      }
    }
    // Distance from q to the outside of the searched cube of cells.
    double bound = std::numeric_limits<double>::infinity();
    const int32_t ci[3] = {c.x, c.y, c.z};
    for (int a = 0; a < 3; ++a) {
      bound = std::min(bound, q_in_G[a] - (ci[a] - r) * size);
      bound = std::min(bound, (ci[a] + r + 1) * size - q_in_G[a]);
    }
    if (bound >= radius) break;
    if (static_cast<int>(out->size()) == k && out->back().squared_distance_m2 <= bound * bound) {
      break;
    }
  }
  return static_cast<int>(out->size());
}

size_t LocalMap::size() const { return impl_->num_points; }
size_t LocalMap::num_cells() const { return impl_->cells.size(); }
const Eigen::Vector3d& LocalMap::center() const { return impl_->center; }

size_t LocalMap::MemoryBytes() const {
  const Impl& m = *impl_;
  size_t bytes = m.cells.bucket_count() * (sizeof(VoxelKey) + sizeof(Cell) + 8) +
                 m.leaf_counts.bucket_count() * (sizeof(VoxelKey) + sizeof(uint32_t) + 8);
  for (const auto& [key, cell] : m.cells) {
    (void)key;
    bytes += cell.points_in_G.capacity() * sizeof(Eigen::Vector3d) +
             cell.observed_ranges_m.capacity() * sizeof(float);
  }
  return bytes;
}

void LocalMap::Clear() {
  const Eigen::Vector3d center = impl_->center;
  *impl_ = Impl();
  impl_->center = center;
  impl_->last_prune_center = center;
  impl_->cell_size = options_.EffectiveCellSize();
  impl_->inv_cell = 1.0 / impl_->cell_size;
  impl_->inv_leaf = 1.0 / options_.leaf_size_m;
}

std::vector<Eigen::Vector3d> LocalMap::Points() const {
  std::vector<Eigen::Vector3d> points;
  points.reserve(impl_->num_points);
  for (const auto& [key, cell] : impl_->cells) {
    (void)key;
    points.insert(points.end(), cell.points_in_G.begin(), cell.points_in_G.end());
  }
  return points;
}

}  // namespace swarmlio::lio
