// LocalMap: the bounded, incrementally built point map around one drone
// (global frame G), with exact k-nearest-neighbour queries.
//
// Structure (chosen by tools/bench/bench_local_map.cc, see docs/local_map.md):
// a hash grid (tsl::robin_map) of cubic search cells of side cell_size_m, each
// holding a small array of points. A second hash counts the points per leaf
// voxel of side leaf_size_m for on-insert downsampling.
//
// Insertion rule (FAST-LIO filter_size_map): a point is added only if its
// leaf voxel (side leaf_size_m, [k*leaf, (k+1)*leaf) per axis) holds fewer
// than max_points_per_leaf points; otherwise it is dropped (first come, first
// kept), or, with replace_range_ratio r > 0, it replaces the leaf's point
// observed from farthest when its own range is below r times that range
// (off by default: docs/local_map.md). Points outside the current box
// (below) and non-finite points are dropped too. Each point keeps the LiDAR
// range it was observed from
// (returned with it by KNearest): a LiDAR's angular noise displaces a point by
// range x angle, which the plane fit's normal noise model uses.
//
// Bounding (FAST-LIO cube_side_length / det_range): the map keeps the axis
// aligned cube of half side half_extent_m around the last UpdateCenter()
// position. UpdateCenter() prunes lazily: only when the centre moved more than
// prune_distance_m since the last prune does it walk the cells (O(cells),
// no point is touched except in removed cells) and erase every cell whose
// centre lies outside the cube. So at any time every stored point is within
// half_extent_m + prune_distance_m + cell_size_m / 2 (infinity norm) of the
// centre.
//
// Queries: KNearest() is exact within max_search_radius_m: it returns the k
// nearest stored points closer than that radius, sorted by squared distance,
// searching cells in growing cubic shells and stopping as soon as the k-th
// distance is below the distance to any unvisited cell. KNearest is const and
// uses no shared scratch, so concurrent queries are safe (not concurrent with
// Insert / UpdateCenter).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/lio/map_neighbor.h"

namespace swarmlio::lio {

struct LocalMapOptions {
  double leaf_size_m = 0.5;        // insertion downsampling voxel (filter_size_map) [m]
  int max_points_per_leaf = 1;     // points kept per leaf voxel
  // A point observed from less than this times the range of a full leaf's
  // farthest-observed point replaces it; 0 = off (first come, first kept) [-].
  double replace_range_ratio = 0.0;
  double cell_size_m = 0.0;        // search-grid cell side; 0 = 4 * leaf_size_m [m]
  double half_extent_m = 100.0;    // half side of the kept cube (cube_side_length / 2) [m]
  double prune_distance_m = 5.0;   // prune after the centre moved this far [m]
  double max_search_radius_m = 2.5;  // kNN ignores farther points (>= sqrt(5 m^2) plane gate) [m]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("leaf_size_m", leaf_size_m,
      FieldSpec::Positive("m", "insertion downsampling voxel (filter_size_map)").WithMax(100.0));
    v("half_extent_m", half_extent_m,
      FieldSpec::Positive("m", "points outside the cube of this half side around the drone "
                               "are removed (cube_side_length / 2)"));
    config::VisitExperimental(v, [&](auto& x) {
      x("max_points_per_leaf", max_points_per_leaf,
        FieldSpec::InRange(1.0, 1000.0, "", "points kept per leaf voxel; more are dropped"));
      x("replace_range_ratio", replace_range_ratio,
        FieldSpec::InRange(0.0, 1.0, "",
                           "a full leaf's farthest-observed point is replaced by one observed from "
                           "closer than this times its range; 0 = first come, first kept"));
      x("cell_size_m", cell_size_m,
        FieldSpec::InRange(0.0, 100.0, "m",
                           "side of the hash-grid search cells; 0 = 4 * leaf_size_m (fastest "
                           "in tools/bench/bench_local_map)"));
      x("prune_distance_m", prune_distance_m,
        FieldSpec::AtLeast(0.0, "m", "the map is pruned when the drone moved this far"));
      x("max_search_radius_m", max_search_radius_m,
        FieldSpec::Positive("m", "nearest-neighbour queries ignore farther points"));
    });
  }

  /// cell_size_m, or 4 * leaf_size_m when it is 0.
  double EffectiveCellSize() const { return cell_size_m > 0.0 ? cell_size_m : 4.0 * leaf_size_m; }

  /// "" when valid, else "key: reason".
  std::string Validate() const;
};

class LocalMap {
 public:
  /// CHECK-fails on invalid options (validate configs before).
  explicit LocalMap(const LocalMapOptions& options);
  ~LocalMap();
  LocalMap(LocalMap&&) noexcept;
  LocalMap& operator=(LocalMap&&) noexcept;

  /// Adds `point_in_G`, observed from `observed_range_m` (0 = unknown), unless
  /// its leaf voxel is full, it is outside the box or not finite. Returns true
  /// when added.
  bool Insert(const Eigen::Vector3d& point_in_G, double observed_range_m = 0.0);
  /// Adds each point in order; `observed_ranges_m` (may be null) parallel to
  /// the points. Returns how many were added.
  int Insert(const std::vector<Eigen::Vector3d>& points_in_G,
             const std::vector<double>* observed_ranges_m = nullptr);

  /// Moves the box centre to the drone position `p_b_in_G` (initially the
  /// origin); prunes when it moved more than prune_distance_m since the last
  /// prune. Returns the number of points removed.
  int UpdateCenter(const Eigen::Vector3d& p_b_in_G);
  /// Moves the centre and prunes now. Returns the number of points removed.
  int RemoveOutside(const Eigen::Vector3d& p_b_in_G);

  /// The (at most) k nearest points within max_search_radius_m of `q_in_G`,
  /// ascending squared distance, into `*out` (cleared first). Returns the count.
  int KNearest(const Eigen::Vector3d& q_in_G, int k, std::vector<Neighbor>* out) const;

  size_t size() const;       // stored points
  size_t num_cells() const;  // occupied search cells
  bool empty() const { return size() == 0; }
  /// Approximate heap use [bytes] (hash tables and point arrays).
  size_t MemoryBytes() const;
  const Eigen::Vector3d& center() const;
  void Clear();

  /// Every stored point (order unspecified, deterministic for a given history).
  std::vector<Eigen::Vector3d> Points() const;

  const LocalMapOptions& options() const { return options_; }

 private:
  struct Impl;
  LocalMapOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::lio
