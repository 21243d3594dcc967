#include "swarmlio/sim/primitives.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool IsRotation(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-9 &&
         std::abs(R.determinant() - 1.0) < 1e-9;
}

}  // namespace

double Aabb::SurfaceArea() const {
  if (IsEmpty()) return 0.0;
  const Eigen::Vector3d e = max - min;
  return 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
}

bool Aabb::IntersectRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& inv_direction,
                        double t_min, double t_max, double* t_enter) const {
  double t0 = t_min;
  double t1 = t_max;
  for (int i = 0; i < 3; ++i) {
    double ta = (min[i] - origin[i]) * inv_direction[i];
    double tb = (max[i] - origin[i]) * inv_direction[i];
    if (ta > tb) std::swap(ta, tb);
    // NaN (0 * inf, origin exactly on a slab of a parallel ray) keeps t0/t1.
    t0 = ta > t0 ? ta : t0;
    t1 = tb < t1 ? tb : t1;
    if (t0 > t1) return false;
  }
  *t_enter = t0;
  return true;
}

Primitive Primitive::AxisAlignedBox(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                    const Material& material) {
  CHECK((min.array() <= max.array()).all()) << "box min must be <= max";
  Primitive p;
  p.type_ = PrimitiveType::kBox;
  p.material_ = material;
  p.center_ = 0.5 * (min + max);
  p.half_extents_ = 0.5 * (max - min);
  p.axis_aligned_ = true;
  p.UpdateBounds();
  return p;
}

Primitive Primitive::OrientedBox(const Eigen::Vector3d& center, const Eigen::Matrix3d& R_frame_box,
                                 const Eigen::Vector3d& half_extents, const Material& material) {
  CHECK(IsRotation(R_frame_box));
  CHECK((half_extents.array() >= 0.0).all());
  Primitive p;
  p.type_ = PrimitiveType::kBox;
  p.material_ = material;
  p.center_ = center;
  p.R_frame_local_ = R_frame_box;
  p.axis_aligned_ = R_frame_box.isIdentity(0.0);
  p.half_extents_ = half_extents;
  p.UpdateBounds();
  return p;
}

Primitive Primitive::Rectangle(const Eigen::Vector3d& center, const Eigen::Matrix3d& R_frame_rect,
                               double half_x, double half_y, const Material& material) {
  CHECK(IsRotation(R_frame_rect));
  CHECK(half_x >= 0.0 && half_y >= 0.0);
  Primitive p;
  p.type_ = PrimitiveType::kRectangle;
  p.material_ = material;
  p.center_ = center;
  p.R_frame_local_ = R_frame_rect;
  p.axis_aligned_ = false;
  p.half_extents_ = Eigen::Vector3d(half_x, half_y, 0.0);
  p.UpdateBounds();
  return p;
}

Primitive Primitive::VerticalCylinder(const Eigen::Vector3d& base_center, double radius,
                                      double height, const Material& material) {
  CHECK(radius > 0.0 && height > 0.0);
  Primitive p;
  p.type_ = PrimitiveType::kCylinder;
  p.material_ = material;
  p.center_ = base_center;
  p.half_extents_ = Eigen::Vector3d(radius, radius, height);
  p.UpdateBounds();
  return p;
}

Primitive Primitive::Triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& c, const Material& material) {
  CHECK((b - a).cross(c - a).norm() > 0.0) << "degenerate triangle";
  Primitive p;
  p.type_ = PrimitiveType::kTriangle;
  p.material_ = material;
  p.center_ = a;
  p.v1_ = b;
  p.v2_ = c;
  p.UpdateBounds();
  return p;
}

void Primitive::UpdateBounds() {
  bounds_ = Aabb();
  switch (type_) {
    case PrimitiveType::kBox:
    case PrimitiveType::kRectangle: {
      // |R| h is the half size of the rotated box's AABB.
      const Eigen::Vector3d e = R_frame_local_.cwiseAbs() * half_extents_;
      bounds_.Extend(center_ - e);
      bounds_.Extend(center_ + e);
      break;
    }
    case PrimitiveType::kCylinder: {
      const double r = half_extents_.x();
      const Eigen::Vector3d axis = R_frame_local_.col(2) * half_extents_.z();
      // Each axis: r * sqrt(1 - axis_i^2) for the disc, plus the axis span.
      for (const Eigen::Vector3d& c : {center_, Eigen::Vector3d(center_ + axis)}) {
        const Eigen::Vector3d u = R_frame_local_.col(2);
        const Eigen::Vector3d ext =
            (Eigen::Vector3d::Ones() - u.cwiseProduct(u)).cwiseMax(0.0).cwiseSqrt() * r;
        bounds_.Extend(c - ext);
        bounds_.Extend(c + ext);
      }
      break;
    }
    case PrimitiveType::kTriangle:
      bounds_.Extend(center_);
      bounds_.Extend(v1_);
      bounds_.Extend(v2_);
      break;
  }
}

Primitive Primitive::Transformed(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) const {
  CHECK(IsRotation(R));
  Primitive out = *this;
  out.center_ = R * center_ + p;
  if (type_ == PrimitiveType::kTriangle) {
    out.v1_ = R * v1_ + p;
    out.v2_ = R * v2_ + p;
  } else {
    out.R_frame_local_ = R * R_frame_local_;
    out.axis_aligned_ = type_ == PrimitiveType::kBox && out.R_frame_local_.isIdentity(0.0);
  }
  out.UpdateBounds();
  return out;
}

bool Primitive::Contains(const Eigen::Vector3d& p) const {
  switch (type_) {
    case PrimitiveType::kBox: {
      const Eigen::Vector3d local = R_frame_local_.transpose() * (p - center_);
      return (local.cwiseAbs().array() < half_extents_.array()).all();
    }
    case PrimitiveType::kCylinder: {
      const double radius = half_extents_.x();
      return p.z() > center_.z() && p.z() < center_.z() + half_extents_.z() &&
             (p.head<2>() - center_.head<2>()).squaredNorm() < radius * radius;
    }
    case PrimitiveType::kRectangle:
    case PrimitiveType::kTriangle:
      return false;
  }
  return false;
}

bool Primitive::Intersect(const Ray& ray, double t_min, double t_max, double* t,
                          Eigen::Vector3d* normal) const {
  switch (type_) {
    case PrimitiveType::kBox:
      return IntersectBox(ray, t_min, t_max, t, normal);
    case PrimitiveType::kRectangle:
      return IntersectRectangle(ray, t_min, t_max, t, normal);
    case PrimitiveType::kCylinder:
      return IntersectCylinder(ray, t_min, t_max, t, normal);
    case PrimitiveType::kTriangle:
      return IntersectTriangle(ray, t_min, t_max, t, normal);
  }
  return false;
}

bool Primitive::IntersectBox(const Ray& ray, double t_min, double t_max, double* t,
                             Eigen::Vector3d* normal) const {
  Eigen::Vector3d o = ray.origin - center_;
  Eigen::Vector3d d = ray.direction;
  if (!axis_aligned_) {
    o = R_frame_local_.transpose() * o;
    d = R_frame_local_.transpose() * d;
  }
  // Slab test, remembering which slab bounds the entry and the exit.
  double t_enter = -kInf;
  double t_exit = kInf;
  int enter_axis = -1;
  int exit_axis = -1;
  double enter_sign = 0.0;
  double exit_sign = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double h = half_extents_[i];
    if (d[i] == 0.0) {
      if (o[i] < -h || o[i] > h) return false;
      continue;
    }
    const double inv = 1.0 / d[i];
    double ta = (-h - o[i]) * inv;
    double tb = (h - o[i]) * inv;
    // Entering through the -h face when d > 0, the +h face when d < 0.
    const double sign_a = -1.0;
    double s_near = sign_a;
    double s_far = -sign_a;
    if (ta > tb) {
      std::swap(ta, tb);
      std::swap(s_near, s_far);
    }
    if (ta > t_enter) {
      t_enter = ta;
      enter_axis = i;
      enter_sign = s_near;
    }
    if (tb < t_exit) {
      t_exit = tb;
      exit_axis = i;
      exit_sign = s_far;
    }
  }
  if (t_enter > t_exit) return false;
  double t_hit;
  int axis;
  double sign;
  if (t_enter >= t_min && t_enter <= t_max) {
    t_hit = t_enter;
    axis = enter_axis;
    sign = enter_sign;
  } else if (t_enter < t_min && t_exit >= t_min && t_exit <= t_max) {
    t_hit = t_exit;  // origin inside the box: hit the inner side of a face
    axis = exit_axis;
    sign = exit_sign;
  } else {
    return false;
  }
  if (axis < 0) return false;  // ray entirely inside a degenerate slab
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[axis] = sign;
  *t = t_hit;
  *normal = axis_aligned_ ? n : Eigen::Vector3d(R_frame_local_ * n);
  return true;
}

bool Primitive::IntersectRectangle(const Ray& ray, double t_min, double t_max, double* t,
                                   Eigen::Vector3d* normal) const {
  const Eigen::Vector3d n = R_frame_local_.col(2);
  const double denom = n.dot(ray.direction);
  if (denom == 0.0) return false;
  const double t_hit = n.dot(center_ - ray.origin) / denom;
  if (!(t_hit >= t_min && t_hit <= t_max)) return false;
  const Eigen::Vector3d q = ray.origin + t_hit * ray.direction - center_;
  if (std::abs(R_frame_local_.col(0).dot(q)) > half_extents_.x() ||
      std::abs(R_frame_local_.col(1).dot(q)) > half_extents_.y()) {
    return false;
  }
  *t = t_hit;
  *normal = n;
  return true;
}

bool Primitive::IntersectCylinder(const Ray& ray, double t_min, double t_max, double* t,
                                  Eigen::Vector3d* normal) const {
  const Eigen::Vector3d o = R_frame_local_.transpose() * (ray.origin - center_);
  const Eigen::Vector3d d = R_frame_local_.transpose() * ray.direction;
  const double r = half_extents_.x();
  const double height = half_extents_.z();
  double best = kInf;
  Eigen::Vector3d best_n = Eigen::Vector3d::Zero();
  // Side: |o_xy + t d_xy|^2 = r^2, with the cancellation-free root formula.
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > 0.0) {
    const double b = o.x() * d.x() + o.y() * d.y();  // half of the linear coefficient
    const double c = o.x() * o.x() + o.y() * o.y() - r * r;
    const double disc = b * b - a * c;
    if (disc >= 0.0) {
      const double q = -(b + std::copysign(std::sqrt(disc), b));
      double roots[2] = {q / a, q != 0.0 ? c / q : q / a};
      if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
      for (double root : roots) {
        if (root < t_min || root > t_max || root >= best) continue;
        const double z = o.z() + root * d.z();
        if (z < 0.0 || z > height) continue;
        best = root;
        best_n = Eigen::Vector3d(o.x() + root * d.x(), o.y() + root * d.y(), 0.0) / r;
        break;
      }
    }
  }
  // Caps at z = 0 and z = height.
  if (d.z() != 0.0) {
    for (double zc : {0.0, height}) {
      const double tc = (zc - o.z()) / d.z();
      if (tc < t_min || tc > t_max || tc >= best) continue;
      const double x = o.x() + tc * d.x();
      const double y = o.y() + tc * d.y();
      if (x * x + y * y > r * r) continue;
      best = tc;
      best_n = Eigen::Vector3d(0.0, 0.0, zc == 0.0 ? -1.0 : 1.0);
    }
  }
  if (best == kInf) return false;
  *t = best;
  *normal = R_frame_local_ * best_n.normalized();
  return true;
}

bool Primitive::IntersectTriangle(const Ray& ray, double t_min, double t_max, double* t,
                                  Eigen::Vector3d* normal) const {
  // Moller-Trumbore.
  const Eigen::Vector3d e1 = v1_ - center_;
  const Eigen::Vector3d e2 = v2_ - center_;
  const Eigen::Vector3d p = ray.direction.cross(e2);
  const double det = e1.dot(p);
  if (det == 0.0) return false;
  const double inv_det = 1.0 / det;
  const Eigen::Vector3d s = ray.origin - center_;
  const double u = s.dot(p) * inv_det;
  if (u < 0.0 || u > 1.0) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = ray.direction.dot(q) * inv_det;
  if (v < 0.0 || u + v > 1.0) return false;
  const double t_hit = e2.dot(q) * inv_det;
  if (!(t_hit >= t_min && t_hit <= t_max)) return false;
  *t = t_hit;
  *normal = e1.cross(e2).normalized();
  return true;
}

}  // namespace swarmlio::sim
