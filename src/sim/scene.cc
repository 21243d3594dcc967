#include "swarmlio/sim/scene.h"

#include <utility>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {

Scene::Scene(Scene&& other) noexcept
    : primitives_(std::move(other.primitives_)), built_(other.built_) {
  if (built_) bvh_.Build(&primitives_);
  other.built_ = false;
}

Scene& Scene::operator=(Scene&& other) noexcept {
  primitives_ = std::move(other.primitives_);
  built_ = other.built_;
  bvh_ = Bvh();
  if (built_) bvh_.Build(&primitives_);
  other.built_ = false;
  return *this;
}

int Scene::Add(const Primitive& primitive) {
  primitives_.push_back(primitive);
  built_ = false;
  return static_cast<int>(primitives_.size()) - 1;
}

void Scene::Build() {
  bvh_.Build(&primitives_);
  built_ = true;
}

bool Scene::Intersect(const Ray& ray, double t_min, double t_max, RayHit* hit) const {
  CHECK(built_) << "Scene::Build() must be called after the last Add()";
  return bvh_.Intersect(ray, t_min, t_max, hit);
}

Aabb Scene::Bounds() const {
  Aabb b;
  for (const Primitive& p : primitives_) b.Extend(p.bounds());
  return b;
}

void AddRoom(const Eigen::Vector3d& floor_center_m, const Eigen::Vector3d& inner_size_m,
             double wall_thickness_m, const Material& material, bool ceiling, Scene* scene) {
  const Eigen::Vector3d& c = floor_center_m;
  const Eigen::Vector3d h(0.5 * inner_size_m.x(), 0.5 * inner_size_m.y(), inner_size_m.z());
  const double w = wall_thickness_m;
  auto box = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    scene->Add(Primitive::AxisAlignedBox(c + lo, c + hi, material));
  };
  box({-h.x() - w, -h.y() - w, -w}, {h.x() + w, h.y() + w, 0.0});  // floor
  if (ceiling) box({-h.x() - w, -h.y() - w, h.z()}, {h.x() + w, h.y() + w, h.z() + w});
  box({-h.x() - w, -h.y() - w, 0.0}, {-h.x(), h.y() + w, h.z()});
  box({h.x(), -h.y() - w, 0.0}, {h.x() + w, h.y() + w, h.z()});
  box({-h.x(), -h.y() - w, 0.0}, {h.x(), -h.y(), h.z()});
  box({-h.x(), h.y(), 0.0}, {h.x(), h.y() + w, h.z()});
}

}  // namespace swarmlio::sim
