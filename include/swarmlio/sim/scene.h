// Static scene: a list of primitives in the world frame W plus a BVH over them.
#pragma once

#include <vector>

#include "swarmlio/sim/bvh.h"
#include "swarmlio/sim/primitives.h"

namespace swarmlio::sim {

class Scene {
 public:
  Scene() = default;
  // The BVH points into primitives_: copying would dangle, moving is fine
  // only through Rebuild, so the scene is move-only and rebuilds on move.
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  Scene(Scene&& other) noexcept;
  Scene& operator=(Scene&& other) noexcept;

  /// Adds a primitive; returns its index. Invalidates the BVH until Build().
  int Add(const Primitive& primitive);
  void Build();
  bool built() const { return built_; }

  /// Closest hit in [t_min, t_max] (BVH; Build() must have been called).
  bool Intersect(const Ray& ray, double t_min, double t_max, RayHit* hit) const;

  const std::vector<Primitive>& primitives() const { return primitives_; }
  const Bvh& bvh() const { return bvh_; }
  /// Bounds of all primitives.
  Aabb Bounds() const;

 private:
  std::vector<Primitive> primitives_;
  Bvh bvh_;
  bool built_ = false;
};

/// Adds a closed room of axis-aligned boxes to `scene`: the inner space is
/// `inner_size_m` (x, y, height) with its floor centred at `floor_center_m`;
/// floor, four walls and (when `ceiling`) the ceiling are `wall_thickness_m`
/// thick.
void AddRoom(const Eigen::Vector3d& floor_center_m, const Eigen::Vector3d& inner_size_m,
             double wall_thickness_m, const Material& material, bool ceiling, Scene* scene);

}  // namespace swarmlio::sim
