#include "swarmlio/teammate/point_removal.h"

namespace swarmlio::teammate {

void FindPointsNear(const std::vector<ScanPoint>& points,
                    const std::vector<Eigen::Vector3d>& centers_in_b, double radius_m,
                    std::vector<int>* indices) {
  indices->clear();
  if (centers_in_b.empty() || radius_m <= 0.0) return;
  std::vector<Eigen::Vector3f> centers;
  centers.reserve(centers_in_b.size());
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = Eigen::Vector3f::Constant(-1e30f);
  const float r = static_cast<float>(radius_m);
  for (const Eigen::Vector3d& c : centers_in_b) {
    centers.push_back(c.cast<float>());
    lo = lo.cwiseMin(centers.back() - Eigen::Vector3f::Constant(r));
    hi = hi.cwiseMax(centers.back() + Eigen::Vector3f::Constant(r));
  }
  const float r2 = r * r;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i].p_in_b;
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
    for (const Eigen::Vector3f& c : centers) {
      if ((p - c).squaredNorm() <= r2) {
        indices->push_back(static_cast<int>(i));
        break;
      }
    }
  }
}

std::vector<ScanPoint> RemovePoints(const std::vector<ScanPoint>& points,
                                    const std::vector<int>& removed) {
  std::vector<ScanPoint> kept;
  kept.reserve(points.size() - removed.size());
  size_t next = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (next < removed.size() && static_cast<size_t>(removed[next]) == i) {
      ++next;
      continue;
    }
    kept.push_back(points[i]);
  }
  return kept;
}

}  // namespace swarmlio::teammate
