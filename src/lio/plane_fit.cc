#include "swarmlio/lio/plane_fit.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"

namespace swarmlio::lio {
namespace {

template <class GetPoint, class GetRange>
PlaneFitStatus FitImpl(int n, const GetPoint& get, const GetRange& get_range,
                       double farthest_sq_distance_m2,
                       const PlaneFitOptions& options, Plane* plane) {
  CHECK(plane != nullptr);
  if (n < options.min_neighbors || n < 3) return PlaneFitStatus::kTooFewPoints;
  if (!(farthest_sq_distance_m2 <= options.max_neighbor_sq_distance_m2)) {
    return PlaneFitStatus::kNeighborsTooFar;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) centroid += get(i);
  centroid /= n;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d e = get(i) - centroid;
    scatter.noalias() += e * e.transpose();
  }
  scatter /= n;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(scatter);  // eigenvalues ascending
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);
  if (!(std::sqrt(lambda(1)) >= options.min_plane_extent_m) || !lambda.allFinite()) {
    return PlaneFitStatus::kDegenerate;
  }
  Eigen::Vector3d normal = eig.eigenvectors().col(0).normalized();
  double offset = -normal.dot(centroid);
  bool flip = offset > 0.0;
  if (offset == 0.0) {
    for (int i = 0; i < 3; ++i) {
      if (normal(i) != 0.0) {
        flip = normal(i) < 0.0;
        break;
      }
    }
  }
  if (flip) {
    normal = -normal;
    offset = -offset;
  }
  double max_abs = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = normal.dot(get(i)) + offset;
    max_abs = std::max(max_abs, std::abs(r));
    sum_sq += r * r;
  }
  if (!(max_abs <= options.max_point_to_plane_m)) return PlaneFitStatus::kNotPlanar;
  const double angular_rad = options.map_angular_stddev_deg * (M_PI / 180.0);
  double sum_var = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = get_range(i);
    sum_var += options.map_range_stddev_m * options.map_range_stddev_m +
               r * r * angular_rad * angular_rad;
  }
  plane->normal_stddev_rad = std::sqrt(sum_var / (static_cast<double>(n) * n * lambda(1)));
  plane->normal_stddev_major_rad =
      std::sqrt(sum_var / (static_cast<double>(n) * n * std::max(lambda(2), lambda(1))));
  plane->tilt_axis_in_G = eig.eigenvectors().col(1).normalized();
  plane->centroid_in_G = centroid;
  plane->normal_in_G = normal;
  plane->offset_m = offset;
  plane->max_abs_residual_m = max_abs;
  plane->rms_residual_m = std::sqrt(sum_sq / n);
  const double sum = lambda.sum();
  plane->curvature = sum > 0.0 ? lambda(0) / sum : 0.0;
  return PlaneFitStatus::kOk;
}

}  // namespace

double Plane::TiltStddevToward(const Eigen::Vector3d& e) const {
  const double along_minor = normal_stddev_rad * tilt_axis_in_G.dot(e);
  const Eigen::Vector3d major = tilt_axis_in_G.cross(normal_in_G);
  const double along_major = normal_stddev_major_rad * major.dot(e);
  return std::sqrt(along_minor * along_minor + along_major * along_major);
}

const char* ToString(PlaneFitStatus status) {
  switch (status) {
    case PlaneFitStatus::kOk:
      return "ok";
    case PlaneFitStatus::kTooFewPoints:
      return "too_few_points";
    case PlaneFitStatus::kNeighborsTooFar:
      return "neighbors_too_far";
    case PlaneFitStatus::kDegenerate:
      return "degenerate";
    case PlaneFitStatus::kNotPlanar:
      return "not_planar";
  }
  return "?";
}

PlaneFitStatus FitPlane(const std::vector<Eigen::Vector3d>& points,
                        double farthest_sq_distance_m2, const PlaneFitOptions& options,
                        Plane* plane) {
  return FitImpl(
      static_cast<int>(points.size()), [&](int i) -> const Eigen::Vector3d& { return points[i]; },
      [](int) { return 0.0; }, farthest_sq_distance_m2, options, plane);
}

PlaneFitStatus FitPlane(const std::vector<Neighbor>& neighbors, const PlaneFitOptions& options,
                        Plane* plane) {
  double farthest = 0.0;
  for (const Neighbor& nb : neighbors) farthest = std::max(farthest, nb.squared_distance_m2);
  return FitImpl(
      static_cast<int>(neighbors.size()),
      [&](int i) -> const Eigen::Vector3d& { return neighbors[i].point_in_G; },
      [&](int i) { return neighbors[i].observed_range_m; }, farthest, options, plane);
}

}  // namespace swarmlio::lio
