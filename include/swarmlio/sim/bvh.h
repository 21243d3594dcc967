// Bounding volume hierarchy over primitive bounding boxes (binned SAH build),
// for closest-hit ray queries against static geometry.
#pragma once

#include <cstdint>
#include <vector>

#include "swarmlio/sim/primitives.h"

namespace swarmlio::sim {

/// Result of a closest-hit query.
struct RayHit {
  double t = std::numeric_limits<double>::infinity();  // ray parameter [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();     // unit geometric normal
  int primitive = -1;                                   // index into the primitive list
  bool hit() const { return primitive >= 0; }
};

/// Closest hit over all `primitives` by testing each one (reference for tests;
/// the ray casts at a few body parts, sim::RayCastReflectiveCentroid).
bool IntersectBruteForce(const std::vector<Primitive>& primitives, const Ray& ray, double t_min,
                         double t_max, RayHit* hit);

class Bvh {
 public:
  struct Options {
    int max_leaf_size = 4;  // primitives per leaf
    int num_bins = 16;      // SAH bins per axis
  };

  Bvh() = default;
  /// Builds over `primitives`, which must outlive the Bvh and stay unchanged.
  void Build(const std::vector<Primitive>* primitives, const Options& options);
  void Build(const std::vector<Primitive>* primitives) { Build(primitives, Options()); }

  /// Closest hit with parameter in [t_min, t_max]; false if none.
  bool Intersect(const Ray& ray, double t_min, double t_max, RayHit* hit) const;
  /// True if anything is hit in [t_min, t_max] (early exit).
  bool Occluded(const Ray& ray, double t_min, double t_max) const;

  int num_nodes() const { return static_cast<int>(nodes_.size()); }
  int depth() const { return depth_; }
  const Aabb& bounds() const;

 private:
  struct Node {
    Aabb bounds;
    int32_t first = 0;  // leaf: first index into order_; inner: index of the left child
    int32_t count = 0;  // leaf: number of primitives; inner: 0 (right child = first + 1)
  };
  int BuildRecursive(int node_index, int begin, int end, int depth, std::vector<Aabb>* boxes,
                     std::vector<Eigen::Vector3d>* centroids);
  template <bool kAnyHit>
  bool Traverse(const Ray& ray, double t_min, double t_max, RayHit* hit) const;

  const std::vector<Primitive>* primitives_ = nullptr;
  Options options_;
  std::vector<Node> nodes_;
  std::vector<int32_t> order_;
  int depth_ = 0;
};

}  // namespace swarmlio::sim
