// The schema of a scenario file (configs/scenarios/*.yaml) as options
// structs read with config::ConfigFile: the scene's primitives, the drones'
// and moving objects' motion and sensors, the swarm generator and the
// imperfections, each with its YAML keys, units and validation, and the
// builders that turn a parsed entry into simulator objects (Make, Build).
// Internal to scenario.cc (docs/simulator.md documents the schema).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/math/angles.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {

enum class PrimitiveKind { kBox, kOrientedBox, kRectangle, kCylinder, kTriangle };
enum class PlanKind { kHover, kHoverUntil, kTakeoff, kTransit, kExcite };

}  // namespace swarmlio::sim

namespace swarmlio::config {
template <>
struct EnumTraits<sim::PrimitiveKind> {
  static constexpr std::array<std::pair<sim::PrimitiveKind, const char*>, 5> kNames{{
      {sim::PrimitiveKind::kBox, "box"},
      {sim::PrimitiveKind::kOrientedBox, "oriented_box"},
      {sim::PrimitiveKind::kRectangle, "rectangle"},
      {sim::PrimitiveKind::kCylinder, "cylinder"},
      {sim::PrimitiveKind::kTriangle, "triangle"},
  }};
};
template <>
struct EnumTraits<sim::SurfaceType> {
  static constexpr std::array<std::pair<sim::SurfaceType, const char*>, 2> kNames{{
      {sim::SurfaceType::kDiffuse, "diffuse"},
      {sim::SurfaceType::kRetroReflective, "retro_reflective"},
  }};
};
template <>
struct EnumTraits<sim::PlanKind> {
  static constexpr std::array<std::pair<sim::PlanKind, const char*>, 5> kNames{{
      {sim::PlanKind::kHover, "hover"},
      {sim::PlanKind::kHoverUntil, "hover_until"},
      {sim::PlanKind::kTakeoff, "takeoff"},
      {sim::PlanKind::kTransit, "transit"},
      {sim::PlanKind::kExcite, "excite"},
  }};
};
template <>
struct EnumTraits<sim::AttitudeMode> {
  static constexpr std::array<std::pair<sim::AttitudeMode, const char*>, 2> kNames{{
      {sim::AttitudeMode::kQuadrotor, "quadrotor"},
      {sim::AttitudeMode::kYawOnly, "yaw_only"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::sim::scenario_file {

using config::FieldSpec;

struct ArenaSpec {
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();  // inner size; 0 = no arena
  Eigen::Vector3d floor_center_m = Eigen::Vector3d::Zero();
  double wall_thickness_m = 0.3;
  double albedo_percent = 60.0;
  bool ceiling = true;
  template <class V>
  void VisitFields(V&& v) {
    v("size_m", size_m, FieldSpec::AtLeast(0.0, "m", "inner size; 0 = no walls"));
    v("floor_center_m", floor_center_m, FieldSpec::Doc("centre of the floor", "m"));
    v("wall_thickness_m", wall_thickness_m, FieldSpec::Positive("m", "wall thickness"));
    v("albedo_percent", albedo_percent, FieldSpec::InRange(0, 100, "%", "wall albedo"));
    v("ceiling", ceiling, FieldSpec::Doc("close the arena with a ceiling"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

struct PrimitiveSpec {
  PrimitiveKind type = PrimitiveKind::kBox;
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d c_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  double height_m = 0.0;
  SurfaceType material = SurfaceType::kDiffuse;
  double reflectivity_percent = 50.0;
  template <class V>
  void VisitFields(V&& v) {
    v("type", type, FieldSpec::Doc("box, oriented_box, rectangle, cylinder, triangle"));
    v("min_m", min_m, FieldSpec::Doc("box: min corner", "m"));
    v("max_m", max_m, FieldSpec::Doc("box: max corner", "m"));
    v("center_m", center_m, FieldSpec::Doc("centre (cylinder: base centre)", "m"));
    v("size_m", size_m, FieldSpec::AtLeast(0.0, "m", "full size (rectangle: x, y)"));
    v("rpy_deg", rpy_deg, FieldSpec::Doc("orientation roll, pitch, yaw", "deg"));
    v("a_m", a_m, FieldSpec::Doc("triangle vertex", "m"));
    v("b_m", b_m, FieldSpec::Doc("triangle vertex", "m"));
    v("c_m", c_m, FieldSpec::Doc("triangle vertex", "m"));
    v("radius_m", radius_m, FieldSpec::AtLeast(0.0, "m", "cylinder radius"));
    v("height_m", height_m, FieldSpec::AtLeast(0.0, "m", "cylinder height"));
    v("material", material, FieldSpec::Doc("diffuse or retro_reflective"));
    v("reflectivity_percent", reflectivity_percent,
      FieldSpec::InRange(0, 100, "%", "albedo (diffuse) or tape gain (retro)"));
  }
  std::string Validate() const {
    std::string e = config::ValidateFields(*this);
    if (!e.empty()) return e;
    switch (type) {
      case PrimitiveKind::kBox:
        if (!((min_m.array() <= max_m.array()).all())) return "max_m: must be >= min_m";
        break;
      case PrimitiveKind::kOrientedBox:
      case PrimitiveKind::kRectangle:
        if (size_m.x() <= 0 || size_m.y() <= 0) return "size_m: must be positive";
        break;
      case PrimitiveKind::kCylinder:
        if (radius_m <= 0 || height_m <= 0) return "radius_m: radius and height must be > 0";
        break;
      case PrimitiveKind::kTriangle:
        if ((b_m - a_m).cross(c_m - a_m).norm() <= 0.0) return "a_m: degenerate triangle";
        break;
    }
    return {};
  }
  Primitive Make() const {
    const Material mat{material, reflectivity_percent};
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(rpy_deg.z() * kRadiansPerDegree, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(rpy_deg.y() * kRadiansPerDegree, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy_deg.x() * kRadiansPerDegree, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    switch (type) {
      case PrimitiveKind::kBox:
        return Primitive::AxisAlignedBox(min_m, max_m, mat);
      case PrimitiveKind::kOrientedBox:
        return Primitive::OrientedBox(center_m, R, 0.5 * size_m, mat);
      case PrimitiveKind::kRectangle:
        return Primitive::Rectangle(center_m, R, 0.5 * size_m.x(), 0.5 * size_m.y(), mat);
      case PrimitiveKind::kCylinder:
        return Primitive::VerticalCylinder(center_m, radius_m, height_m, mat);
      case PrimitiveKind::kTriangle:
        break;
    }
    return Primitive::Triangle(a_m, b_m, c_m, mat);
  }
};

struct PlanStepSpec {
  PlanKind kind = PlanKind::kHover;
  double duration_s = 0.0;
  double until_s = 0.0;
  double height_m = 1.0;
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  double yaw_deg = 0.0;
  Eigen::Vector3d amplitude_m = Eigen::Vector3d(1.0, 1.0, 0.3);
  double yaw_amplitude_deg = 30.0;
  double period_s = 2.0;
  template <class V>
  void VisitFields(V&& v) {
    v("kind", kind, FieldSpec::Doc("hover, hover_until, takeoff, transit, excite"));
    v("duration_s", duration_s, FieldSpec::AtLeast(0.0, "s", "hover / excite duration"));
    v("until_s", until_s, FieldSpec::AtLeast(0.0, "s", "hover_until: end time"));
    v("height_m", height_m, FieldSpec::Doc("takeoff: climb", "m"));
    v("target_m", target_m, FieldSpec::Doc("transit: target position in W", "m"));
    v("yaw_deg", yaw_deg, FieldSpec::InRange(-720, 720, "deg", "transit: final yaw"));
    v("amplitude_m", amplitude_m, FieldSpec::AtLeast(0.0, "m", "excite: half range per axis"));
    v("yaw_amplitude_deg", yaw_amplitude_deg,
      FieldSpec::InRange(0, 180, "deg", "excite: yaw half range"));
    v("period_s", period_s, FieldSpec::Positive("s", "excite: time per random target"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }

  void AppendTo(TrajectoryBuilder* b) const {
    switch (kind) {
      case PlanKind::kHover:
        b->Hover(duration_s);
        break;
      case PlanKind::kHoverUntil:
        b->Hover(until_s - b->duration());
        break;
      case PlanKind::kTakeoff:
        b->Takeoff(height_m);
        break;
      case PlanKind::kTransit:
        b->TransitTo(target_m, yaw_deg * kRadiansPerDegree);
        break;
      case PlanKind::kExcite:
        b->Excite(duration_s, amplitude_m, yaw_amplitude_deg * kRadiansPerDegree, period_s);
        break;
    }
  }
};

// Where a drone or moving object starts and how it flies; its keys sit
// directly in the drone's or object's YAML map.
struct MotionSpec {
  std::string name;  // drones: "uav<i+1>" when empty
  Eigen::Vector3d start_m = Eigen::Vector3d::Zero();
  double start_yaw_deg = 0.0;
  AttitudeMode attitude = AttitudeMode::kQuadrotor;
  TrajectoryBuilderOptions trajectory;
  std::vector<PlanStepSpec> plan;
  template <class V>
  void VisitFields(V&& v) {
    v("name", name, FieldSpec::Doc("unique name"));
    v("start_m", start_m, FieldSpec::Doc("start position of the body in W", "m"));
    v("start_yaw_deg", start_yaw_deg, FieldSpec::InRange(-360, 360, "deg", "start yaw"));
    v("attitude", attitude, FieldSpec::Doc("quadrotor or yaw_only"));
    v("trajectory", trajectory);
    v("plan", plan, FieldSpec::Doc("flight plan, run in order after the start"));
  }
  Trajectory Build(uint64_t seed, double duration_s) const {
    TrajectoryBuilder b(start_m, start_yaw_deg * kRadiansPerDegree, trajectory, seed);
    for (const PlanStepSpec& step : plan) step.AppendTo(&b);
    return b.Build(0.0, duration_s + 1.0, attitude);
  }
};

// The `body:` map as read in the first pass: its keys and types are checked,
// its values only once applied over the defaults of its `model`
// (ResolveDroneBody in scenario.cc), since they may rely on them.
struct DeferredBody {
  DroneBodyOptions options;
  template <class V>
  void VisitFields(V&& v) {
    options.VisitFields(v);
  }
  std::string Validate() const { return {}; }
};

struct DroneSpec {
  MotionSpec motion;
  std::string sensor_preset;  // "" = the sensor structs' defaults
  double clock_offset_s = 0.0;
  double clock_drift_ppm = 0.0;
  SimulatedLidarOptions lidar;
  SimulatedImuOptions imu;
  DeferredBody body;  // the airframe, resolved by ResolveDroneBody (scenario.cc)
  template <class V>
  void VisitFields(V&& v) {
    motion.VisitFields(v);
    v("sensor_preset", sensor_preset,
      FieldSpec::Doc("sensor preset (configs/*.yaml) under the lidar: and imu: keys"));
    v("clock_offset_s", clock_offset_s,
      FieldSpec::InRange(-100, 100, "s", "clock - true time at t = 0"));
    v("clock_drift_ppm", clock_drift_ppm,
      FieldSpec::InRange(-1000, 1000, "ppm", "clock rate error (plus imperfections.clock)"));
    v("lidar", lidar);
    v("imu", imu);
    v("body", body, FieldSpec::Doc("airframe: `model` and overrides of its defaults"));
  }
  std::string Validate() const {
    // The sensors are validated once merged over the preset and the
    // scenario's imperfections (ResolveDroneSensors).
    DroneSpec without_sensors = *this;
    without_sensors.lidar = SimulatedLidarOptions();
    without_sensors.imu = SimulatedImuOptions();
    return config::ValidateFields(without_sensors);
  }
};

struct ObjectSpec {
  ObjectSpec() { motion.attitude = AttitudeMode::kYawOnly; }
  MotionSpec motion;
  std::vector<PrimitiveSpec> parts;
  template <class V>
  void VisitFields(V&& v) {
    motion.VisitFields(v);
    v("parts", parts, FieldSpec::Doc("primitives in the object's body frame"));
  }
  std::string Validate() const {
    if (parts.empty()) return "parts: needs at least one part";
    return config::ValidateFields(*this);
  }
};

struct SceneSpec {
  ArenaSpec arena;
  std::vector<PrimitiveSpec> primitives;
  template <class V>
  void VisitFields(V&& v) {
    v("arena", arena);
    v("primitives", primitives, FieldSpec::Doc("static primitives in W"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

// Swarm generator: N drones on a grid in a large arena with pillars.
struct GeneratorSpec {
  int num_drones = 0;
  Eigen::Vector3d arena_size_m = Eigen::Vector3d(80, 80, 15);
  int num_pillars = 40;
  double spacing_m = 3.0;
  double flight_height_m = 2.0;
  std::vector<std::string> sensor_presets = {"livox_mid360.yaml", "livox_avia.yaml"};
  template <class V>
  void VisitFields(V&& v) {
    v("num_drones", num_drones, FieldSpec::InRange(0, 40, "", "drones to generate"));
    v("arena_size_m", arena_size_m, FieldSpec::Positive("m", "arena inner size"));
    v("num_pillars", num_pillars, FieldSpec::InRange(0, 10000, "", "random pillars"));
    v("spacing_m", spacing_m, FieldSpec::Positive("m", "start grid spacing"));
    v("flight_height_m", flight_height_m, FieldSpec::Positive("m", "take-off height"));
    v("sensor_presets", sensor_presets,
      FieldSpec::Doc("drone i uses preset i modulo their number; none: defaults"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

// The `imperfections:` map as read in the first pass: its keys and types are
// checked, its values only once applied over the preset for each drone's
// LiDAR type (ScenarioImperfections), since they may rely on the preset.
struct DeferredImperfections {
  // No `imperfections:` key, or a map without `preset:`: realistic (the
  // simulator's default since the honest-accuracy issue; docs/simulator.md).
  DeferredImperfections() { options.preset = ImperfectionPreset::kRealistic; }
  ImperfectionOptions options;
  template <class V>
  void VisitFields(V&& v) {
    options.VisitFields(v);
  }
  std::string Validate() const { return {}; }
};

// The whole scenario file.
struct ScenarioFile {
  ScenarioOptions scenario;
  io::BagWriterOptions bag;
  SceneSpec scene;
  std::vector<DroneSpec> drones;
  std::vector<ObjectSpec> objects;
  GeneratorSpec generator;
  // `imperfections: realistic` names a preset; a map is a preset plus keys.
  bool imperfections_by_name = false;
  ImperfectionPreset imperfections_preset = ImperfectionPreset::kIdeal;
  DeferredImperfections imperfections;
  template <class V>
  void VisitFields(V&& v) {
    v("scenario", scenario);
    v("bag", bag);
    v("scene", scene);
    v("drones", drones, FieldSpec::Doc("the drones, each with sensors and a flight plan"));
    v("objects", objects, FieldSpec::Doc("moving decoys"));
    v("generator", generator);
    if (imperfections_by_name) {
      v("imperfections", imperfections_preset, FieldSpec::Doc("sensor imperfections preset"));
    } else {
      v("imperfections", imperfections, FieldSpec::Doc("sensor imperfections"));
    }
  }
  std::string Validate() const { return config::ValidateFields(*this); }
  ImperfectionPreset preset() const {
    return imperfections_by_name ? imperfections_preset : imperfections.options.preset;
  }
};

}  // namespace swarmlio::sim::scenario_file
