#include "swarmlio/sim/airframe_description.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "swarmlio/sim/bvh.h"

namespace swarmlio::sim {
namespace {

constexpr double kRaySpacingM = 0.004;
// Sparse reflectors: the returns a teammate 3-6 m away gets per scan (2-7 on
// the simulated shell, docs/simulator.md), for the centroid's scatter.
constexpr double kSparseReturnsPerScan = 4.0;

Aabb BoundsOf(const std::vector<Primitive>& parts) {
  Aabb box;
  for (const Primitive& p : parts) box.Extend(p.bounds());
  return box;
}

// Directions at elevations -10, 0 and +10 deg, every 10 deg of azimuth: the
// views of teammates flying at similar heights.
std::vector<Eigen::Vector3d> ViewDirections() {
  std::vector<Eigen::Vector3d> u;
  for (double elevation_deg : {-10.0, 0.0, 10.0}) {
    const double e = elevation_deg * M_PI / 180.0;
    for (int k = 0; k < 36; ++k) {
      const double a = k * 10.0 * M_PI / 180.0;
      u.emplace_back(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    }
  }
  return u;
}

bool IsSparse(const std::vector<Primitive>& parts) {
  for (const Primitive& p : parts) {
    if (p.material().type != SurfaceType::kDiffuse && p.material().return_probability < 1.0) {
      return true;
    }
  }
  return false;
}

}  // namespace

bool RayCastReflectiveCentroid(const std::vector<Primitive>& parts_b,
                               const Eigen::Vector3d& u_in_b,
                               double spacing_m,
                               Eigen::Vector3d* centroid_in_b,
                               double* spread_m) {
  const Aabb box = BoundsOf(parts_b);
  const Eigen::Vector3d centre = box.Center();
  const double radius = 0.5 * (box.max - box.min).norm();
  const Eigen::Vector3d u = u_in_b.normalized();
  const Eigen::Vector3d e1 = u.unitOrthogonal();
  const Eigen::Vector3d e2 = u.cross(e1);
  const int n = static_cast<int>(std::ceil(radius / spacing_m));
  double weight = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      Ray ray;
      ray.origin = centre + 2.0 * radius * u + (i * spacing_m) * e1 + (j * spacing_m) * e2;
      ray.direction = -u;
      double through = 1.0, t_min = 0.0;
      RayHit hit;
      while (through > 1e-6 && IntersectBruteForce(parts_b, ray, t_min,
                                                   std::numeric_limits<double>::infinity(), &hit)) {
        const Material& m = parts_b[static_cast<size_t>(hit.primitive)].material();
        if (m.type == SurfaceType::kDiffuse) break;
        const Eigen::Vector3d p = ray.origin + hit.t * ray.direction;
        const double w = through * m.return_probability;
        weight += w;
        sum += w * p;
        second += w * p * p.transpose();
        through *= 1.0 - m.return_probability;
        t_min = hit.t + 1e-6;
      }
    }
  }
  if (weight <= 0.0) return false;
  *centroid_in_b = sum / weight;
  if (spread_m != nullptr) {
    const Eigen::Matrix3d cov = second / weight - *centroid_in_b * centroid_in_b->transpose();
    *spread_m = std::sqrt(std::max(0.0, cov.trace()));
  }
  return true;
}

teammate::AirframeDescription DescribeAirframe(const DroneBodyOptions& body) {
  using teammate::ReflectorShape;
  const std::vector<Primitive> parts = MakeDroneBody(body);
  teammate::AirframeDescription a;
  const Aabb box = BoundsOf(parts);
  a.size_m = (box.max - box.min).norm();
  a.reflector_centre_in_body_m = ReflectiveCentroidInBody(parts);
  const bool shell = body.model == AirframeModel::kReflectiveShell;
  a.min_intensity = shell ? body.shell_intensity_min : body.tape_intensity_min;
  if (body.tape_height_m > 0.0 && body.arm_tape_fraction <= 0.0 && !shell) {
    // A band around the core: its faces lie just outside the core's.
    a.reflector_shape = ReflectorShape::kBand;
    for (const Primitive& p : parts) {
      if (p.material().type != SurfaceType::kDiffuse) a.reflector_half_extents_m = p.half_extents();
    }
    a.depth_offset_m = 0.0;
    return a;
  }
  // Round: the mean depth of the returns' centroid over the views, and for a
  // sparse reflector the scatter of the centroid of a few returns.
  a.reflector_shape = ReflectorShape::kRound;
  a.reflector_half_extents_m = 0.5 * (box.max - box.min);
  double depth = 0.0, spread = 0.0;
  int views = 0;
  for (const Eigen::Vector3d& u : ViewDirections()) {
    Eigen::Vector3d centroid;
    double s = 0.0;
    if (!RayCastReflectiveCentroid(parts, u, kRaySpacingM, &centroid, &s)) continue;
    depth += (centroid - a.reflector_centre_in_body_m).dot(u);
    spread += s;
    ++views;
  }
  if (views > 0) {
    a.depth_offset_m = std::max(0.0, depth / views);
    if (IsSparse(parts)) a.centroid_sigma_m = spread / views / std::sqrt(kSparseReturnsPerScan);
  }
  return a;
}

}  // namespace swarmlio::sim
