// The simulated drone's body as seen by teammates' LiDARs: an airframe model
// of a few primitives in the body (IMU) frame b carrying retro-reflective
// parts, and the moving object type shared by drones and moving decoys.
//
// Airframes (`body: {model: <name>, ...}` in a scenario; docs/simulator.md,
// "Airframes"). The model chooses the defaults of every other field
// (DroneBodyOptions::ForModel) and the geometry; the scenario's keys override
// the defaults where they apply.
//
//   tape_band (default): core box 0.20 x 0.14 x 0.15 m centred on b, a 5 cm band
//     of retro-reflective tape around its middle, two crossed 0.35 m arms
//     (0.03 x 0.024 m) at z = core_z / 8. Reflective centroid: b's origin.
//   arm_tape: a larger frame, core 0.28 x 0.20 x 0.12 m, arms 0.60 m, no band;
//     the outer half of each of the four arm ends is taped (tape 0.15 m long,
//     0.15-0.30 m from the centre). Reflective centroid: (0, 0, core_z / 8) =
//     (0, 0, 0.015) m; a LiDAR sees mostly the near arm ends, so the centroid
//     of its returns lies towards it, off the origin.
//   reflective_shell: only a closed flat disc (vertical cylinder) 0.35 m in
//     diameter, 0.08 m high, centred on b, a sparse reflective lattice: each
//     ray crossing it returns with probability 0.5 (else passes through, so
//     returns come from its near and far sides), at a constant intensity
//     uniform in the integers 236-255. Reflective centroid: b's origin.
//   dim_tape: tape_band's geometry with a tape whose intensity spans
//     [100, 145] instead of [151, 255]: at 2-10 m it returns about what a 90 %
//     diffuse surface does (~134 at 4.5 m head-on; the diffuse model caps at
//     150), so intensity alone cannot tell it from the brightest scenery.
//     Reflective centroid: b's origin.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/sim/primitives.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

enum class AirframeModel { kTapeBand, kArmTape, kReflectiveShell, kDimTape };

}  // namespace swarmlio::sim

namespace swarmlio::config {
template <>
struct EnumTraits<sim::AirframeModel> {
  static constexpr std::array<std::pair<sim::AirframeModel, const char*>, 4> kNames{{
      {sim::AirframeModel::kTapeBand, "tape_band"},
      {sim::AirframeModel::kArmTape, "arm_tape"},
      {sim::AirframeModel::kReflectiveShell, "reflective_shell"},
      {sim::AirframeModel::kDimTape, "dim_tape"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::sim {

/// The defaults are those of `tape_band`; ForModel() gives another model's.
/// Frame fields (arm_*, core_*, tape_*, body_albedo_percent) apply to
/// tape_band, arm_tape and dim_tape; shell_* fields to reflective_shell.
struct DroneBodyOptions {
  AirframeModel model = AirframeModel::kTapeBand;
  double arm_span_m = 0.35;          // tip-to-tip length of each of the two crossed arms
  Eigen::Vector3d core_size_m = Eigen::Vector3d(0.20, 0.14, 0.15);  // central box
  double tape_height_m = 0.05;  // height of the retro-reflective band around the core; 0 = none
  double tape_gain_percent = 100.0;  // 100 = new tape
  double body_albedo_percent = 15.0;
  double arm_tape_fraction = 0.0;     // outer fraction of each arm end that is taped; 0 = none
  double tape_intensity_min = 151.0;  // band of the tape's intensity, Livox 0-255
  double tape_intensity_max = 255.0;
  double shell_diameter_m = 0.35;
  double shell_height_m = 0.08;
  double shell_return_probability = 0.5;  // per ray crossing the shell
  double shell_intensity_min = 236.0;     // constant intensity, uniform integers, Livox 0-255
  double shell_intensity_max = 255.0;

  /// The defaults of `model` (the header comment lists them).
  static DroneBodyOptions ForModel(AirframeModel model);

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("model", model, FieldSpec::Doc("airframe model, its defaults under the other keys"));
    v("arm_span_m", arm_span_m, FieldSpec::Positive("m", "tip-to-tip length of each arm"));
    v("core_size_m", core_size_m, FieldSpec::Positive("m", "central box size x, y, z"));
    v("tape_height_m", tape_height_m,
      FieldSpec::AtLeast(0.0, "m", "height of the tape band around the core, 0 = none"));
    v("tape_gain_percent", tape_gain_percent,
      FieldSpec::InRange(0.0, 100.0, "%", "tape gain, 100 = new tape"));
    v("body_albedo_percent", body_albedo_percent,
      FieldSpec::InRange(0.0, 100.0, "%", "diffuse albedo of the body"));
    v("arm_tape_fraction", arm_tape_fraction,
      FieldSpec::InRange(0.0, 1.0, "", "outer fraction of each arm end that is taped, 0 = none"));
    v("tape_intensity_min", tape_intensity_min,
      FieldSpec::InRange(0.0, 255.0, "", "lowest intensity of the tape (Livox 0-255)"));
    v("tape_intensity_max", tape_intensity_max,
      FieldSpec::InRange(0.0, 255.0, "", "highest intensity of the tape (Livox 0-255)"));
    v("shell_diameter_m", shell_diameter_m,
      FieldSpec::Positive("m", "reflective_shell: diameter of the flat disc"));
    v("shell_height_m", shell_height_m,
      FieldSpec::Positive("m", "reflective_shell: height of the flat disc"));
    v("shell_return_probability", shell_return_probability,
      FieldSpec::Positive("",
                          "reflective_shell: probability that a ray crossing the shell "
                          "returns from it")
          .WithMax(1.0));
    v("shell_intensity_min", shell_intensity_min,
      FieldSpec::InRange(0.0, 255.0, "", "reflective_shell: lowest intensity (Livox 0-255)"));
    v("shell_intensity_max", shell_intensity_max,
      FieldSpec::InRange(0.0, 255.0, "", "reflective_shell: highest intensity (Livox 0-255)"));
  }
  std::string Validate() const;
};

/// Parts in the body frame b. tape_band, arm_tape, dim_tape: core box, tape
/// band (slightly larger than the core so that side hits in the band land on
/// tape), two crossed arms, then the tape on the arm ends (each slightly larger
/// than its arm). reflective_shell: the shell alone.
std::vector<Primitive> MakeDroneBody(const DroneBodyOptions& options);

/// Centroid of the reflective (non-diffuse) parts in the body frame b [m],
/// weighted by their surface area (a box's or cylinder's centre); zero when
/// there are none.
Eigen::Vector3d ReflectiveCentroidInBody(const std::vector<Primitive>& parts_b);

/// Geometry that moves along a trajectory: parts are in its body frame.
struct MovingObject {
  std::string name;
  const Trajectory* trajectory = nullptr;
  std::vector<Primitive> parts_b;
  double bounding_radius_m = 0.0;  // around the body origin; computed by Finalize()
  void Finalize();
};

}  // namespace swarmlio::sim
