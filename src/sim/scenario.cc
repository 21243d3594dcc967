// Scenario parsing: the whole file is one options struct (ScenarioFile) read
// with config::ConfigFile; lists (drones, objects, primitives, plan steps) are
// std::vector fields of options structs. Drones with a `sensor_preset` get
// their sensors re-read over the preset after the first pass.
#include "swarmlio/sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/sensor_preset.h"
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

namespace swarmlio::sim {
namespace {

using config::FieldSpec;

constexpr double kDeg = M_PI / 180.0;

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
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(rpy_deg.z() * kDeg, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(rpy_deg.y() * kDeg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(rpy_deg.x() * kDeg, Eigen::Vector3d::UnitX()))
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
        b->TransitTo(target_m, yaw_deg * kDeg);
        break;
      case PlanKind::kExcite:
        b->Excite(duration_s, amplitude_m, yaw_amplitude_deg * kDeg, period_s);
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
    TrajectoryBuilder b(start_m, start_yaw_deg * kDeg, trajectory, seed);
    for (const PlanStepSpec& step : plan) step.AppendTo(&b);
    return b.Build(0.0, duration_s + 1.0, attitude);
  }
};

struct DroneSpec {
  MotionSpec motion;
  std::string sensor_preset;  // "" = the sensor structs' defaults
  double clock_offset_s = 0.0;
  double clock_drift_ppm = 0.0;
  SimulatedLidarOptions lidar;
  SimulatedImuOptions imu;
  DroneBodyOptions body;
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
    v("body", body);
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

// Scenario-level imperfections for a drone whose LiDAR is of `type`: the
// values of `preset` with the file's `imperfections:` keys over them.
Status ScenarioImperfections(const config::ConfigFile& file,
                             const ScenarioFile& spec,
                             ImperfectionPreset preset,
                             LidarType type,
                             ImperfectionOptions* imperfections) {
  ImperfectionOptions o = ImperfectionOptions::ForPreset(preset, type);
  if (!spec.imperfections_by_name) SWARMLIO_RETURN_IF_ERROR(file.Read("imperfections", &o));
  o.preset = preset;
  *imperfections = o;
  return Status::Ok();
}

// The per-drone draws of the scenario-level imperfections: clock drift and
// calibration error of drone `index`.
void DrawDroneImperfections(const ImperfectionOptions& imperfections,
                            uint64_t seed,
                            size_t index,
                            DroneConfig* drone) {
  if (imperfections.clock.drift_sigma_ppm > 0.0) {
    drone->clock_drift_ppm +=
        DrawClockDriftPpm(imperfections.clock, DeriveSeed(seed, index, streams::kClockDrift));
  }
  if (imperfections.calibration.Any()) {
    drone->calibration_error = DrawCalibrationError(
        imperfections.calibration, DeriveSeed(seed, index, streams::kCalibrationError));
  }
}

// The sensors of preset `path` (a key of `file` names it in errors) with
// nothing else set: the simulation-only settings keep their defaults.
Status LoadPresetSensors(const config::ConfigFile& file,
                         const std::string& key,
                         const std::string& path,
                         SimulatedLidarOptions* lidar,
                         SimulatedImuOptions* imu) {
  *lidar = SimulatedLidarOptions();
  *imu = SimulatedImuOptions();
  const Status status = config::LoadSensorPreset(path, &lidar->sensor, &imu->sensor);
  return status.ok() ? status : file.KeyError(key, status.message());
}

// Sets the drone's sensors: its preset (or the defaults) with the scenario's
// imperfections for its LiDAR type, then the drone's own `lidar:` and `imu:`
// keys read over them (and validated). *imperfections: the scenario level.
Status ResolveDroneSensors(const config::ConfigFile& file,
                           const ScenarioFile& spec,
                           ImperfectionPreset preset,
                           const std::string& key,
                           const std::filesystem::path& preset_dir,
                           DroneSpec* drone,
                           ImperfectionOptions* imperfections) {
  SimulatedLidarOptions lidar;
  SimulatedImuOptions imu;
  if (!drone->sensor_preset.empty()) {
    SWARMLIO_RETURN_IF_ERROR(LoadPresetSensors(
        file, key + ".sensor_preset", (preset_dir / drone->sensor_preset).string(), &lidar, &imu));
  }
  // The drone's own type when it sets one (the first pass read it), else the preset's.
  const LidarType type =
      file.HasKey(key + ".lidar.type") ? drone->lidar.sensor.type : lidar.sensor.type;
  SWARMLIO_RETURN_IF_ERROR(ScenarioImperfections(file, spec, preset, type, imperfections));
  lidar.imperfections = imperfections->lidar;
  imu.imperfections = imperfections->imu;
  SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".lidar", &lidar));
  SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".imu", &imu));
  drone->lidar = lidar;
  drone->imu = imu;
  return Status::Ok();
}

void AddArena(const ArenaSpec& a, Scene* scene) {
  if ((a.size_m.array() <= 0.0).any()) return;
  AddRoom(a.floor_center_m, a.size_m, a.wall_thickness_m, Material::Diffuse(a.albedo_percent),
          a.ceiling, scene);
}

Status Generate(const config::ConfigFile& file,
                const ScenarioFile& spec,
                ImperfectionPreset preset,
                const std::filesystem::path& preset_dir,
                uint64_t seed,
                double duration_s,
                Scenario* s) {
  const GeneratorSpec& g = spec.generator;
  std::vector<SimulatedLidarOptions> lidars(g.sensor_presets.size());
  std::vector<SimulatedImuOptions> imus(g.sensor_presets.size());
  for (size_t j = 0; j < g.sensor_presets.size(); ++j) {
    SWARMLIO_RETURN_IF_ERROR(
        LoadPresetSensors(file, "generator." + config::IndexKey("sensor_presets", j),
                          (preset_dir / g.sensor_presets[j]).string(), &lidars[j], &imus[j]));
  }
  std::mt19937_64 rng(DeriveSeed(seed, 0xfeed, 0));
  std::uniform_real_distribution<double> ux(-0.45 * g.arena_size_m.x(), 0.45 * g.arena_size_m.x());
  std::uniform_real_distribution<double> uy(-0.45 * g.arena_size_m.y(), 0.45 * g.arena_size_m.y());
  std::uniform_real_distribution<double> ur(0.2, 1.0);
  ArenaSpec arena;
  arena.size_m = g.arena_size_m;
  arena.ceiling = false;
  AddArena(arena, &s->scene);
  const int cols = static_cast<int>(std::ceil(std::sqrt(std::max(1, g.num_drones))));
  const double grid = g.spacing_m * (cols + 2);
  for (int i = 0; i < g.num_pillars; ++i) {
    const double x = ux(rng), y = uy(rng);
    if (std::abs(x) < grid && std::abs(y) < grid) continue;  // keep the start area free
    s->scene.Add(Primitive::VerticalCylinder({x, y, 0.0}, ur(rng), g.arena_size_m.z() * ur(rng),
                                             Material::Diffuse(30.0 + 50.0 * ur(rng))));
  }
  for (int i = 0; i < g.num_drones; ++i) {
    DroneConfig d;
    d.name = "uav" + std::to_string(i + 1);
    const Eigen::Vector3d start((i % cols - 0.5 * (cols - 1)) * g.spacing_m,
                                (i / cols - 0.5 * (cols - 1)) * g.spacing_m, 0.1);
    TrajectoryBuilder b(start, 0.0, TrajectoryBuilderOptions(),
                        DeriveSeed(seed, i, streams::kTrajectory));
    b.Hover(3.0);
    b.Takeoff(g.flight_height_m + 0.3 * (i % 3));
    b.Excite(std::max(4.0, duration_s - b.duration() - 2.0), Eigen::Vector3d(1.0, 1.0, 0.3), 0.5,
             2.0);
    d.trajectory = b.Build(0.0, duration_s + 1.0);
    if (!lidars.empty()) {
      d.lidar = lidars[static_cast<size_t>(i) % lidars.size()];
      d.imu = imus[static_cast<size_t>(i) % imus.size()];
    }
    ImperfectionOptions imperfections;
    SWARMLIO_RETURN_IF_ERROR(
        ScenarioImperfections(file, spec, preset, d.lidar.sensor.type, &imperfections));
    d.lidar.imperfections = imperfections.lidar;
    d.imu.imperfections = imperfections.imu;
    DrawDroneImperfections(imperfections, seed, s->drones.size(), &d);
    s->drones.push_back(std::move(d));
  }
  return Status::Ok();
}

}  // namespace

SimulationConfig Scenario::simulation_config() const {
  SimulationConfig c;
  c.duration_s = options.duration_s;
  c.seed = static_cast<uint64_t>(options.seed);
  c.stamp_origin_s = options.stamp_origin_s;
  c.ground_truth_rate_hz = options.ground_truth_rate_hz;
  c.num_threads = options.num_threads;
  return c;
}

namespace {

std::string DescribeSolid(const Primitive& p) {
  std::ostringstream os;
  os.precision(3);
  const Aabb& b = p.bounds();
  os << (p.type() == PrimitiveType::kCylinder ? "cylinder" : "box") << " spanning ["
     << b.min.x() << ", " << b.min.y() << ", " << b.min.z() << "] to [" << b.max.x() << ", "
     << b.max.y() << ", " << b.max.z() << "] m";
  return os.str();
}

// A flight through a solid is physically impossible, and the simulated LiDAR
// then sees the solid's inside faces. The body origin is sampled every
// kFlightCheckStepS (6 cm at 3 m/s) against every closed primitive.
constexpr double kFlightCheckStepS = 0.02;

Status CheckFlightsClearScene(const config::ConfigFile& file, const Scenario& s,
                              size_t num_listed_drones, double duration_s) {
  const std::vector<Primitive>& solids = s.scene.primitives();
  for (size_t i = 0; i < s.drones.size(); ++i) {
    const Trajectory& trajectory = s.drones[i].trajectory;
    const int steps = static_cast<int>(std::ceil(duration_s / kFlightCheckStepS));
    for (int k = 0; k <= steps; ++k) {
      const double t = std::min(duration_s, k * kFlightCheckStepS);
      const Eigen::Vector3d p = trajectory.PositionAt(t);
      for (const Primitive& solid : solids) {
        const Aabb& b = solid.bounds();
        if ((p.array() <= b.min.array()).any() || (p.array() >= b.max.array()).any()) continue;
        if (!solid.Contains(p)) continue;
        std::ostringstream os;
        os.precision(4);
        os << "the flight of '" << s.drones[i].name << "' passes through a " << DescribeSolid(solid)
           << " at t = " << t << " s (body at [" << p.x() << ", " << p.y() << ", " << p.z()
           << "] m): add a waypoint around it";
        return file.KeyError(
            i < num_listed_drones ? config::IndexKey("drones", i) + ".plan" : "generator",
            os.str());
      }
    }
  }
  return Status::Ok();
}

Status BuildScenario(const config::ConfigFile& file,
                     const ScenarioOverrides& overrides,
                     Scenario* scenario) {
  ScenarioFile spec;
  spec.imperfections_by_name = file.HasKey("imperfections") && !file.HasSection("imperfections");
  SWARMLIO_RETURN_IF_ERROR(file.Read("", &spec));
  const ImperfectionPreset preset = overrides.imperfections.value_or(spec.preset());
  // Each drone's bag is written in its own LiDAR's format (lidar.message_format).
  for (const char* key : {"bag.lidar_format", "bag.point_time_unit"}) {
    if (file.HasKey(key)) {
      return file.KeyError(key,
                           "set per drone by its lidar.message_format and lidar.timestamp_unit");
    }
  }
  const std::filesystem::path preset_dir =
      std::filesystem::path(file.name()).parent_path() / spec.scenario.preset_dir;
  const uint64_t seed = static_cast<uint64_t>(spec.scenario.seed);
  const double duration_s = spec.scenario.duration_s;

  Scenario s;
  s.options = spec.scenario;
  s.bag = spec.bag;
  s.imperfections = preset;
  AddArena(spec.scene.arena, &s.scene);
  for (const PrimitiveSpec& p : spec.scene.primitives) s.scene.Add(p.Make());

  for (size_t i = 0; i < spec.drones.size(); ++i) {
    DroneSpec& d = spec.drones[i];
    const std::string key = config::IndexKey("drones", i);
    ImperfectionOptions imperfections;
    SWARMLIO_RETURN_IF_ERROR(
        ResolveDroneSensors(file, spec, preset, key, preset_dir, &d, &imperfections));
    DroneConfig c;
    c.name = d.motion.name.empty() ? "uav" + std::to_string(i + 1) : d.motion.name;
    c.trajectory = d.motion.Build(DeriveSeed(seed, i, streams::kTrajectory), duration_s);
    c.lidar = d.lidar;
    c.imu = d.imu;
    c.body = d.body;
    c.clock_offset_s = d.clock_offset_s;
    c.clock_drift_ppm = d.clock_drift_ppm;
    DrawDroneImperfections(imperfections, seed, i, &c);
    s.drones.push_back(std::move(c));
  }
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    const ObjectSpec& o = spec.objects[i];
    MovingObjectConfig c;
    c.name = o.motion.name.empty() ? "object" + std::to_string(i + 1) : o.motion.name;
    c.trajectory = o.motion.Build(DeriveSeed(seed, 1000 + i, streams::kTrajectory), duration_s);
    for (const PrimitiveSpec& p : o.parts) c.parts_b.push_back(p.Make());
    s.objects.push_back(std::move(c));
  }
  if (spec.generator.num_drones > 0) {
    SWARMLIO_RETURN_IF_ERROR(Generate(file, spec, preset, preset_dir, seed, duration_s, &s));
  }

  if (s.drones.empty()) return file.KeyError("drones", "the scenario has no drones");
  for (size_t i = 0; i < s.drones.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (s.drones[i].name == s.drones[j].name) {
        return file.KeyError(config::IndexKey("drones", i) + ".name",
                             "duplicate name '" + s.drones[i].name + "'");
      }
    }
  }
  SWARMLIO_RETURN_IF_ERROR(CheckFlightsClearScene(file, s, spec.drones.size(), duration_s));
  s.scene.Build();
  *scenario = std::move(s);
  return Status::Ok();
}

}  // namespace

Status ParseScenario(const std::string& yaml_text,
                     const std::string& name,
                     Scenario* scenario,
                     const ScenarioOverrides& overrides) {
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Parse(yaml_text, name, &file));
  return BuildScenario(file, overrides, scenario);
}

Status LoadScenario(const std::string& path,
                    Scenario* scenario,
                    const ScenarioOverrides& overrides) {
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Load(path, &file));
  return BuildScenario(file, overrides, scenario);
}

}  // namespace swarmlio::sim
