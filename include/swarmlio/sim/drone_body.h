// The simulated drone's body as seen by teammates' LiDARs: a few boxes in the
// body (IMU) frame carrying a band of retro-reflective tape, and the moving
// object type shared by drones and moving decoys.
#pragma once

#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sim/primitives.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

struct DroneBodyOptions {
  double arm_span_m = 0.35;          // tip-to-tip length of each of the two crossed arms
  Eigen::Vector3d core_size_m = Eigen::Vector3d(0.20, 0.14, 0.15);  // central box
  double tape_height_m = 0.05;       // height of the retro-reflective band around the core
  double tape_gain_percent = 100.0;  // 100 = new tape
  double body_albedo_percent = 15.0;

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("arm_span_m", arm_span_m, FieldSpec::Positive("m", "tip-to-tip length of each arm"));
    v("core_size_m", core_size_m, FieldSpec::Positive("m", "central box size x, y, z"));
    v("tape_height_m", tape_height_m, FieldSpec::AtLeast(0.0, "m", "height of the tape band"));
    v("tape_gain_percent", tape_gain_percent,
      FieldSpec::InRange(0.0, 100.0, "%", "tape gain, 100 = new tape"));
    v("body_albedo_percent", body_albedo_percent,
      FieldSpec::InRange(0.0, 100.0, "%", "diffuse albedo of the body"));
  }
  std::string Validate() const;
};

/// Parts in the body frame: core box, tape band (slightly larger than the core
/// so that side hits in the band land on tape) and two crossed arms.
std::vector<Primitive> MakeDroneBody(const DroneBodyOptions& options);

/// Geometry that moves along a trajectory: parts are in its body frame.
struct MovingObject {
  std::string name;
  const Trajectory* trajectory = nullptr;
  std::vector<Primitive> parts_b;
  double bounding_radius_m = 0.0;  // around the body origin; computed by Finalize()
  void Finalize();
};

}  // namespace swarmlio::sim
