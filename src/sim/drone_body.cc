#include "swarmlio/sim/drone_body.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/math/so3.h"

namespace swarmlio::sim {
namespace {

// Arms: cross-section half extents (y, z) [m], their centre height as a
// fraction of the core's half height, and the tape's margin around its part.
constexpr double kArmHalfWidthM = 0.015;
constexpr double kArmHalfThicknessM = 0.012;
constexpr double kArmHeightFraction = 0.25;
constexpr double kTapeMarginM = 0.002;

Material TapeMaterial(const DroneBodyOptions& o) {
  return Material::RetroReflectiveBand(o.tape_gain_percent, o.tape_intensity_min,
                                       o.tape_intensity_max);
}

// The taped outer `arm_tape_fraction` of both ends of the arm along `R_b_arm`'s x.
void AddArmTape(const DroneBodyOptions& o,
                const Eigen::Vector3d& arm_center,
                const Eigen::Matrix3d& R_b_arm,
                std::vector<Primitive>* parts) {
  const double half_span = 0.5 * o.arm_span_m;
  const double half_length = 0.5 * o.arm_tape_fraction * half_span + 0.5 * kTapeMarginM;
  const Eigen::Vector3d half_tape(half_length, kArmHalfWidthM + kTapeMarginM,
                                  kArmHalfThicknessM + kTapeMarginM);
  for (double side : {1.0, -1.0}) {
    const double along = side * (half_span + kTapeMarginM - half_length);
    parts->push_back(Primitive::OrientedBox(arm_center + R_b_arm.col(0) * along, R_b_arm, half_tape,
                                            TapeMaterial(o)));
  }
}

// Core, band, arms and arm tape (tape_band, arm_tape, dim_tape).
std::vector<Primitive> MakeFrame(const DroneBodyOptions& o) {
  std::vector<Primitive> parts;
  const Material body = Material::Diffuse(o.body_albedo_percent);
  const Eigen::Vector3d half_core = 0.5 * o.core_size_m;
  parts.push_back(Primitive::AxisAlignedBox(-half_core, half_core, body));
  if (o.tape_height_m > 0.0) {
    const Eigen::Vector3d half_tape(half_core.x() + kTapeMarginM, half_core.y() + kTapeMarginM,
                                    0.5 * o.tape_height_m);
    parts.push_back(Primitive::AxisAlignedBox(-half_tape, half_tape, TapeMaterial(o)));
  }
  const Eigen::Vector3d half_arm(0.5 * o.arm_span_m, kArmHalfWidthM, kArmHalfThicknessM);
  const Eigen::Vector3d arm_center(0, 0, kArmHeightFraction * half_core.z());
  const double angles[] = {M_PI / 4, -M_PI / 4};
  for (double angle : angles) {
    parts.push_back(
        Primitive::OrientedBox(arm_center, so3::Exp(Eigen::Vector3d(0, 0, angle)), half_arm, body));
  }
  if (o.arm_tape_fraction > 0.0) {
    for (double angle : angles) {
      AddArmTape(o, arm_center, so3::Exp(Eigen::Vector3d(0, 0, angle)), &parts);
    }
  }
  return parts;
}

// A closed flat disc centred on the body origin, a sparse lattice of constant
// high intensity (reflective_shell).
std::vector<Primitive> MakeShell(const DroneBodyOptions& o) {
  const Material shell = Material::ConstantIntensity(o.shell_intensity_min, o.shell_intensity_max,
                                                     o.shell_return_probability);
  return {Primitive::VerticalCylinder(Eigen::Vector3d(0, 0, -0.5 * o.shell_height_m),
                                      0.5 * o.shell_diameter_m, o.shell_height_m, shell)};
}

}  // namespace

DroneBodyOptions DroneBodyOptions::ForModel(AirframeModel model) {
  DroneBodyOptions o;
  o.model = model;
  switch (model) {
    case AirframeModel::kTapeBand:
    case AirframeModel::kReflectiveShell:
      break;
    case AirframeModel::kArmTape:
      o.arm_span_m = 0.60;
      o.core_size_m = Eigen::Vector3d(0.28, 0.20, 0.12);
      o.tape_height_m = 0.0;
      o.arm_tape_fraction = 0.5;
      break;
    case AirframeModel::kDimTape:
      o.tape_intensity_min = 100.0;
      o.tape_intensity_max = 145.0;
      break;
  }
  return o;
}

std::string DroneBodyOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  if (tape_height_m > core_size_m.z()) return "tape_height_m: must not exceed core_size_m[2]";
  if (tape_intensity_min >= tape_intensity_max) {
    return "tape_intensity_max: must be above tape_intensity_min";
  }
  if (std::ceil(shell_intensity_min) > std::floor(shell_intensity_max)) {
    return "shell_intensity_max: the band [shell_intensity_min, shell_intensity_max] holds no "
           "integer intensity";
  }
  return {};
}

std::vector<Primitive> MakeDroneBody(const DroneBodyOptions& o) {
  return o.model == AirframeModel::kReflectiveShell ? MakeShell(o) : MakeFrame(o);
}

Eigen::Vector3d ReflectiveCentroidInBody(const std::vector<Primitive>& parts_b) {
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (const Primitive& p : parts_b) {
    if (p.material().type == SurfaceType::kDiffuse) continue;
    const Eigen::Vector3d& h = p.half_extents();
    double area = 0.0;
    Eigen::Vector3d center = p.center();
    if (p.type() == PrimitiveType::kBox) {
      area = 8.0 * (h.x() * h.y() + h.y() * h.z() + h.z() * h.x());
    } else if (p.type() == PrimitiveType::kCylinder) {  // h = (radius, radius, height)
      area = 2.0 * M_PI * h.x() * (h.x() + h.z());
      center += p.rotation().col(2) * (0.5 * h.z());
    } else {
      area = p.bounds().SurfaceArea();  // flat parts: not used by the airframes
      center = p.bounds().Center();
    }
    weighted += area * center;
    total += area;
  }
  return total > 0.0 ? Eigen::Vector3d(weighted / total) : Eigen::Vector3d::Zero();
}

void MovingObject::Finalize() {
  bounding_radius_m = 0.0;
  for (const Primitive& p : parts_b) {
    const Aabb& b = p.bounds();
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c((corner & 1) ? b.max.x() : b.min.x(),
                              (corner & 2) ? b.max.y() : b.min.y(),
                              (corner & 4) ? b.max.z() : b.min.z());
      bounding_radius_m = std::max(bounding_radius_m, c.norm());
    }
  }
}

}  // namespace swarmlio::sim
