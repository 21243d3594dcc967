// Scenario parsing: the whole file is one options struct (ScenarioFile) read
// with config::ConfigFile; lists (drones, objects, primitives, plan steps) are
// std::vector fields of options structs. Drones with a `sensor_preset` get
// their sensors re-read over the preset after the first pass.
#include "swarmlio/sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/sensor_preset.h"
#include "scenario_file.h"
#include "swarmlio/sim/flight_clearance.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

using namespace scenario_file;  // NOLINT: the schema structs, scenario_file.h

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

// The drone's airframe: the defaults of its `body.model`, with its `body:`
// keys read over them (and validated).
Status ResolveDroneBody(const config::ConfigFile& file,
                        const std::string& key,
                        const DroneSpec& drone,
                        DroneBodyOptions* body) {
  DroneBodyOptions resolved = DroneBodyOptions::ForModel(drone.body.options.model);
  SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".body", &resolved));
  *body = resolved;
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

// A flight through a solid is refused at the key that planned it.
Status CheckFlightsClearScene(const config::ConfigFile& file, const Scenario& s,
                              size_t num_listed_drones, double duration_s) {
  const std::optional<FlightThroughSolid> hit =
      FindFlightThroughSolid(s.scene.primitives(), s.drones, duration_s);
  if (!hit) return Status::Ok();
  return file.KeyError(
      hit->drone < num_listed_drones ? config::IndexKey("drones", hit->drone) + ".plan"
                                     : "generator",
      hit->Describe(s.drones[hit->drone].name));
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
    SWARMLIO_RETURN_IF_ERROR(ResolveDroneBody(file, key, d, &c.body));
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
