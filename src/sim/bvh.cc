#include "swarmlio/sim/bvh.h"

#include <algorithm>
#include <array>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {
namespace {

constexpr int kMaxStack = 128;

Eigen::Vector3d InverseDirection(const Eigen::Vector3d& d) {
  return Eigen::Vector3d(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());
}

}  // namespace

bool IntersectBruteForce(const std::vector<Primitive>& primitives, const Ray& ray, double t_min,
                         double t_max, RayHit* hit) {
  *hit = RayHit();
  double best = t_max;
  for (size_t i = 0; i < primitives.size(); ++i) {
    double t;
    Eigen::Vector3d n;
    if (primitives[i].Intersect(ray, t_min, best, &t, &n) && (!hit->hit() || t < best)) {
      best = t;
      hit->t = t;
      hit->normal = n;
      hit->primitive = static_cast<int>(i);
    }
  }
  return hit->hit();
}

const Aabb& Bvh::bounds() const {
  static const Aabb kEmpty;
  return nodes_.empty() ? kEmpty : nodes_[0].bounds;
}

void Bvh::Build(const std::vector<Primitive>* primitives, const Options& options) {
  CHECK(primitives != nullptr);
  CHECK_GE(options.max_leaf_size, 1);
  CHECK_GE(options.num_bins, 2);
  primitives_ = primitives;
  options_ = options;
  nodes_.clear();
  order_.clear();
  depth_ = 0;
  const int n = static_cast<int>(primitives->size());
  if (n == 0) return;
  std::vector<Aabb> boxes(n);
  std::vector<Eigen::Vector3d> centroids(n);
  order_.resize(n);
  for (int i = 0; i < n; ++i) {
    boxes[i] = (*primitives)[i].bounds();
    centroids[i] = boxes[i].Center();
    order_[i] = i;
  }
  nodes_.reserve(2 * n);
  nodes_.emplace_back();
  BuildRecursive(0, 0, n, 1, &boxes, &centroids);
}

int Bvh::BuildRecursive(int node_index, int begin, int end, int depth, std::vector<Aabb>* boxes,
                        std::vector<Eigen::Vector3d>* centroids) {
  depth_ = std::max(depth_, depth);
  Aabb bounds;
  Aabb centroid_bounds;
  for (int i = begin; i < end; ++i) {
    bounds.Extend((*boxes)[order_[i]]);
    centroid_bounds.Extend((*centroids)[order_[i]]);
  }
  nodes_[node_index].bounds = bounds;
  const int count = end - begin;
  auto make_leaf = [&] {
    nodes_[node_index].first = begin;
    nodes_[node_index].count = count;
    return node_index;
  };
  if (count <= options_.max_leaf_size || depth >= kMaxStack - 8) return make_leaf();

  // Binned SAH over all three axes.
  const int num_bins = options_.num_bins;
  double best_cost = std::numeric_limits<double>::infinity();
  int best_axis = -1;
  int best_split = -1;
  const Eigen::Vector3d extent = centroid_bounds.max - centroid_bounds.min;
  std::vector<Aabb> bin_bounds(num_bins);
  std::vector<int> bin_count(num_bins);
  std::vector<double> right_area(num_bins);
  std::vector<int> right_count(num_bins);
  auto bin_of = [&](int p, int axis) {
    const double scale = num_bins / extent[axis];
    return std::min(num_bins - 1, static_cast<int>(((*centroids)[p][axis] -
                                                    centroid_bounds.min[axis]) * scale));
  };
  for (int axis = 0; axis < 3; ++axis) {
    if (!(extent[axis] > 0.0)) continue;
    std::fill(bin_bounds.begin(), bin_bounds.end(), Aabb());
    std::fill(bin_count.begin(), bin_count.end(), 0);
    for (int i = begin; i < end; ++i) {
      const int p = order_[i];
      const int b = bin_of(p, axis);
      bin_count[b]++;
      bin_bounds[b].Extend((*boxes)[p]);
    }
    Aabb acc;
    int acc_count = 0;
    for (int b = num_bins - 1; b > 0; --b) {
      acc.Extend(bin_bounds[b]);
      acc_count += bin_count[b];
      right_area[b] = acc.SurfaceArea();
      right_count[b] = acc_count;
    }
    acc = Aabb();
    acc_count = 0;
    for (int b = 0; b < num_bins - 1; ++b) {
      acc.Extend(bin_bounds[b]);
      acc_count += bin_count[b];
      if (acc_count == 0 || right_count[b + 1] == 0) continue;
      const double cost = acc.SurfaceArea() * acc_count + right_area[b + 1] * right_count[b + 1];
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_split = b;
      }
    }
  }
  int mid = begin + count / 2;  // all centroids coincide: split the list in the middle
  if (best_axis >= 0) {
    if (count <= 2 * options_.max_leaf_size && best_cost >= bounds.SurfaceArea() * count) {
      return make_leaf();
    }
    int32_t* split = std::partition(order_.data() + begin, order_.data() + end,
                                    [&](int32_t p) { return bin_of(p, best_axis) <= best_split; });
    mid = static_cast<int>(split - order_.data());
    if (mid == begin || mid == end) mid = begin + count / 2;
  }
  const int left = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node_index].first = left;
  nodes_[node_index].count = 0;
  BuildRecursive(left, begin, mid, depth + 1, boxes, centroids);
  BuildRecursive(left + 1, mid, end, depth + 1, boxes, centroids);
  return node_index;
}

bool Bvh::Intersect(const Ray& ray, double t_min, double t_max, RayHit* hit) const {
  *hit = RayHit();
  return Traverse<false>(ray, t_min, t_max, hit);
}

bool Bvh::Occluded(const Ray& ray, double t_min, double t_max) const {
  RayHit hit;
  return Traverse<true>(ray, t_min, t_max, &hit);
}

template <bool kAnyHit>
bool Bvh::Traverse(const Ray& ray, double t_min, double t_max, RayHit* hit) const {
  if (nodes_.empty()) return false;
  const Eigen::Vector3d inv_dir = InverseDirection(ray.direction);
  double best = t_max;
  std::array<int32_t, kMaxStack> stack;
  int top = 0;
  double t_enter;
  if (!nodes_[0].bounds.IntersectRay(ray.origin, inv_dir, t_min, best, &t_enter)) return false;
  stack[top++] = 0;
  const std::vector<Primitive>& prims = *primitives_;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        double t;
        Eigen::Vector3d n;
        const int p = order_[i];
        if (prims[p].Intersect(ray, t_min, best, &t, &n)) {
          // Ties: keep the lower primitive index, as the brute force does.
          if (!hit->hit() || t < best || (t == best && p < hit->primitive)) {
            best = t;
            hit->t = t;
            hit->normal = n;
            hit->primitive = p;
            if (kAnyHit) return true;
          }
        }
      }
      continue;
    }
    const int left = node.first;
    double t_left;
    double t_right;
    const bool hit_left = nodes_[left].bounds.IntersectRay(ray.origin, inv_dir, t_min, best, &t_left);
    const bool hit_right =
        nodes_[left + 1].bounds.IntersectRay(ray.origin, inv_dir, t_min, best, &t_right);
    if (hit_left && hit_right) {
      // Visit the nearer child first (pushed last).
      if (t_left <= t_right) {
        stack[top++] = left + 1;
        stack[top++] = left;
      } else {
        stack[top++] = left;
        stack[top++] = left + 1;
      }
    } else if (hit_left) {
      stack[top++] = left;
    } else if (hit_right) {
      stack[top++] = left + 1;
    }
  }
  return hit->hit();
}

}  // namespace swarmlio::sim
