// Scene primitives of the simulator: finite geometric shapes with a surface
// material, and exact ray intersection against each of them.
//
// All shapes are closed or two-sided, so a ray hits them from any side.
// Frames: every primitive is stored in the frame it was built in (the world
// frame W for static scenery, the body frame for a drone's parts).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

namespace swarmlio::sim {

/// A ray origin + t * direction, t >= 0. `direction` must be unit length.
struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

enum class SurfaceType { kDiffuse, kRetroReflective, kConstantIntensity };

/// Surface material. For kDiffuse, `reflectivity_percent` is the Lambertian
/// albedo (0-100 %); for kRetroReflective it is the tape's gain relative to a
/// fresh tape (0-100 %, 100 = new tape), and the returned intensity lies in
/// [intensity_min, intensity_max] (the Livox retro-reflective range 151-255 by
/// default; a lower band models a dim tape, reflectivity.h). kConstantIntensity
/// returns an intensity drawn uniformly from the integers in [intensity_min,
/// intensity_max] whatever the range and incidence. `return_probability` < 1
/// makes the surface a sparse lattice: each ray crossing it returns from it
/// with that probability and otherwise passes through (lidar_model.h).
struct Material {
  SurfaceType type = SurfaceType::kDiffuse;
  double reflectivity_percent = 50.0;
  double intensity_min = 151.0;     // Livox 0-255 (retro-reflective, constant intensity)
  double intensity_max = 255.0;     // Livox 0-255
  double return_probability = 1.0;  // per ray crossing the surface, in (0, 1]

  static Material Diffuse(double percent) { return {SurfaceType::kDiffuse, percent}; }
  static Material RetroReflective(double gain_percent = 100.0) {
    return {SurfaceType::kRetroReflective, gain_percent};
  }
  /// Tape whose intensity spans [intensity_min, intensity_max] instead of 151-255.
  static Material RetroReflectiveBand(double gain_percent,
                                      double intensity_min,
                                      double intensity_max) {
    return {SurfaceType::kRetroReflective, gain_percent, intensity_min, intensity_max};
  }
  static Material ConstantIntensity(double intensity_min,
                                    double intensity_max,
                                    double return_probability = 1.0) {
    return {SurfaceType::kConstantIntensity, 100.0, intensity_min, intensity_max,
            return_probability};
  }
};

/// Axis-aligned bounding box; default constructed it is empty (min > max).
struct Aabb {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());

  bool IsEmpty() const { return (min.array() > max.array()).any(); }
  void Extend(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void Extend(const Aabb& b) {
    min = min.cwiseMin(b.min);
    max = max.cwiseMax(b.max);
  }
  Eigen::Vector3d Center() const { return 0.5 * (min + max); }
  /// Surface area; 0 for an empty box.
  double SurfaceArea() const;
  /// Slab test. `inv_direction` is 1/direction per axis (may be +-inf).
  /// On overlap of [t_min, t_max] with the box returns true and the entry
  /// parameter (clamped to t_min) in *t_enter.
  bool IntersectRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& inv_direction,
                    double t_min, double t_max, double* t_enter) const;
};

enum class PrimitiveType { kBox, kRectangle, kCylinder, kTriangle };

/// One finite shape. Build with the static factories.
class Primitive {
 public:
  /// Box [min, max] aligned with the axes of its frame.
  static Primitive AxisAlignedBox(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                  const Material& material);
  /// Box with centre, orientation R_frame_box and half extents along its axes [m].
  static Primitive OrientedBox(const Eigen::Vector3d& center, const Eigen::Matrix3d& R_frame_box,
                               const Eigen::Vector3d& half_extents, const Material& material);
  /// Two-sided rectangle in the local x-y plane of R_frame_rect (normal = its z
  /// axis), |x| <= half_x, |y| <= half_y.
  static Primitive Rectangle(const Eigen::Vector3d& center, const Eigen::Matrix3d& R_frame_rect,
                             double half_x, double half_y, const Material& material);
  /// Closed cylinder with vertical axis (frame z) from base_center.z to
  /// base_center.z + height.
  static Primitive VerticalCylinder(const Eigen::Vector3d& base_center, double radius,
                                    double height, const Material& material);
  /// Two-sided triangle.
  static Primitive Triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c, const Material& material);

  PrimitiveType type() const { return type_; }
  const Material& material() const { return material_; }
  void set_material(const Material& material) { material_ = material; }
  const Aabb& bounds() const { return bounds_; }

  /// Closest intersection with parameter in [t_min, t_max]. On a hit returns
  /// true, the parameter in *t and the unit geometric normal (outward for
  /// closed shapes, the frame's z / (b-a)x(c-a) side for flat ones) in *normal.
  bool Intersect(const Ray& ray, double t_min, double t_max, double* t,
                 Eigen::Vector3d* normal) const;

  /// Whether `p` (in the primitive's frame) lies strictly inside a closed
  /// shape (box, cylinder); rectangles and triangles contain nothing.
  bool Contains(const Eigen::Vector3d& p) const;

  /// The same primitive expressed in another frame: x_new = R * x + p.
  Primitive Transformed(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) const;

  // Shape parameters (read-only; meaning depends on type()).
  const Eigen::Vector3d& center() const { return center_; }
  const Eigen::Matrix3d& rotation() const { return R_frame_local_; }
  const Eigen::Vector3d& half_extents() const { return half_extents_; }

 private:
  void UpdateBounds();
  bool IntersectBox(const Ray& ray, double t_min, double t_max, double* t,
                    Eigen::Vector3d* normal) const;
  bool IntersectRectangle(const Ray& ray, double t_min, double t_max, double* t,
                          Eigen::Vector3d* normal) const;
  bool IntersectCylinder(const Ray& ray, double t_min, double t_max, double* t,
                         Eigen::Vector3d* normal) const;
  bool IntersectTriangle(const Ray& ray, double t_min, double t_max, double* t,
                         Eigen::Vector3d* normal) const;

  PrimitiveType type_ = PrimitiveType::kBox;
  Material material_;
  // Box/rectangle: centre, orientation, half extents (rectangle: z = 0).
  // Cylinder: centre = base centre, half_extents = (radius, radius, height).
  // Triangle: vertices a = center_, b = v1_, c = v2_.
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_frame_local_ = Eigen::Matrix3d::Identity();
  bool axis_aligned_ = true;
  Eigen::Vector3d half_extents_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v1_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v2_ = Eigen::Vector3d::Zero();
  Aabb bounds_;
};

}  // namespace swarmlio::sim
