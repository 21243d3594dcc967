#include "swarmlio/driver/manifest.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <set>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/sensor_preset.h"

namespace swarmlio::driver {
namespace {

using config::FieldSpec;

struct DroneEntry {
  std::string name;
  std::string bag;
  std::string ground_truth;
  eval::GroundTruthFrame ground_truth_frame = eval::GroundTruthFrame::kAuto;
  std::string teammate_returns;
  std::string sensor_preset;
  LidarOptions lidar;
  ImuOptions imu;
  io::BagReaderOptions bag_topics;
  lio::OdometryOptions odometry;
  teammate::TeammateDetectorOptions teammate;
  swarm::SwarmOptions swarm;
  teammate::AirframeDescription airframe;
  TrueClock true_clock;
  double start_offset_s = 0.0;
  double restart_at_s = 0.0;
  double restart_down_s = 1.0;
  lio::InitializationMode restart_initialization = lio::InitializationMode::kInFlight;
  Eigen::Vector3d p_G_in_W_m = Eigen::Vector3d::Zero();
  std::vector<double> q_W_G_xyzw = {0.0, 0.0, 0.0, 1.0};

  template <class V>
  void VisitFields(V&& v) {
    v("name", name, FieldSpec::Doc("drone name (unique; used for output files)"));
    v("bag", bag, FieldSpec::Doc("ROS1 bag, relative to the manifest's folder"));
    v("ground_truth", ground_truth,
      FieldSpec::Doc("TUM ground-truth file, relative to the manifest's folder (optional)"));
    v("ground_truth_frame", ground_truth_frame,
      FieldSpec::Doc("frame of the ground truth: G (the estimator's: NEES is reported), other "
                     "(mocap/simulator world: aligned, no NEES) or auto (G when it starts at "
                     "the estimate's first pose)"));
    v("teammate_returns", teammate_returns,
      FieldSpec::Doc("simulator truth: CSV of the returns each scan had on each teammate, "
                     "relative to the manifest's folder (optional; evaluation only)"));
    v("sensor_preset", sensor_preset,
      FieldSpec::Doc("sensor preset (lidar: and imu: sections), relative to the manifest"));
    v("lidar", lidar);
    v("imu", imu);
    v("bag_topics", bag_topics);
    v("odometry", odometry);
    v("teammate", teammate);
    v("swarm", swarm);
    v("airframe", airframe);
    v("true_clock", true_clock);
    v("start_offset_s", start_offset_s,
      FieldSpec::InRange(0.0, 1e6, "s",
                         "skip the log's first seconds: the drone starts later (a late join or "
                         "a restart in flight; pair with odometry: {initialization: in_flight})"));
    v("restart_at_s", restart_at_s,
      FieldSpec::InRange(0.0, 1e6, "s",
                         "kill the drone's estimator this far into its log and start a new "
                         "session restart_down_s later (0 = never)"));
    v("restart_down_s", restart_down_s,
      FieldSpec::InRange(0.0, 1e3, "s", "time the restarted drone is down"));
    v("restart_initialization", restart_initialization,
      FieldSpec::Doc("odometry.initialization of the restarted session: in_flight (default) or "
                     "static"));
    v("p_G_in_W_m", p_G_in_W_m,
      FieldSpec::InRange(-1e7, 1e7, "m", "origin of G in a common world frame (plots only)"));
    v("q_W_G_xyzw", q_W_G_xyzw,
      FieldSpec::InRange(-1.0, 1.0, "", "rotation G -> W as a unit quaternion x y z w (plots only)"));
  }
  std::string Validate() const {
    // Sensors and odometry are validated once merged over the preset.
    DroneEntry rest = *this;
    rest.lidar = LidarOptions();
    rest.imu = ImuOptions();
    rest.odometry = lio::OdometryOptions();
    const std::string invalid = config::ValidateFields(rest);
    if (!invalid.empty()) return invalid;
    if (name.empty()) return "name: must not be empty";
    if (bag.empty()) return "bag: must be given";
    if (q_W_G_xyzw.size() != 4) return "q_W_G_xyzw: needs 4 values (x y z w)";
    const double norm = std::sqrt(q_W_G_xyzw[0] * q_W_G_xyzw[0] + q_W_G_xyzw[1] * q_W_G_xyzw[1] +
                                  q_W_G_xyzw[2] * q_W_G_xyzw[2] + q_W_G_xyzw[3] * q_W_G_xyzw[3]);
    if (std::abs(norm - 1.0) > 1e-6) return "q_W_G_xyzw: must be a unit quaternion";
    return "";
  }
};

struct ManifestFile {
  std::string name;
  std::vector<DroneEntry> drones;
  template <class V>
  void VisitFields(V&& v) {
    v("name", name, FieldSpec::Doc("name of the run"));
    v("drones", drones, FieldSpec::Doc("one entry per drone"));
  }
  std::string Validate() const {
    if (drones.empty()) return "drones: at least one drone is needed";
    return config::ValidateFields(*this);
  }
};

std::string Resolve(const std::filesystem::path& folder, const std::string& path) {
  if (path.empty()) return "";
  const std::filesystem::path p(path);
  return p.is_absolute() ? p.string() : (folder / p).lexically_normal().string();
}

}  // namespace

int64_t TrueClock::ToDrone(int64_t true_ns) const {
  const double origin_ns = origin_s * 1e9;
  const double t_ns = static_cast<double>(true_ns) - origin_ns;
  return std::llround(origin_ns + t_ns * (1.0 + drift_ppm * 1e-6) + offset_s * 1e9);
}

int64_t TrueClock::ToTrue(int64_t drone_ns) const {
  const double origin_ns = origin_s * 1e9;
  const double clock_ns = static_cast<double>(drone_ns) - origin_ns - offset_s * 1e9;
  return std::llround(origin_ns + clock_ns / (1.0 + drift_ppm * 1e-6));
}

lio::OdometryOptions DefaultOdometryOptions(const LidarOptions& lidar, const ImuOptions& imu) {
  lio::OdometryOptions odometry = lio::OdometryOptionsFor(lidar);
  odometry.imu_init.acceleration_unit = imu.acceleration_unit == AccelerationUnit::kStandardGravity
                                            ? lio::AccelerationUnitSetting::kStandardGravity
                                            : lio::AccelerationUnitSetting::kMetersPerSecondSquared;
  odometry.imu_init.nominal_gravity_m_s2 = imu.gravity_m_s2;
  return odometry;
}

Status ParseManifest(const std::string& yaml_text, const std::string& name,
                     SwarmManifest* manifest) {
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Parse(yaml_text, name, &file));
  ManifestFile spec;
  SWARMLIO_RETURN_IF_ERROR(file.Read("", &spec));
  const std::filesystem::path folder = std::filesystem::path(name).parent_path();
  SwarmManifest out;
  out.name = spec.name;
  std::set<std::string> names;
  for (size_t i = 0; i < spec.drones.size(); ++i) {
    const DroneEntry& e = spec.drones[i];
    const std::string key = config::IndexKey("drones", i);
    if (!names.insert(e.name).second) {
      return file.KeyError(key + ".name", "duplicate drone name '" + e.name + "'");
    }
    DroneInput d;
    d.name = e.name;
    d.bag_path = Resolve(folder, e.bag);
    d.ground_truth_path = Resolve(folder, e.ground_truth);
    d.ground_truth_frame = e.ground_truth_frame;
    if (!e.teammate_returns.empty()) d.teammate_returns_path = Resolve(folder, e.teammate_returns);
    d.bag = e.bag_topics;
    d.airframe = e.airframe;
    d.true_clock = e.true_clock;
    d.start_offset_s = e.start_offset_s;
    d.restart_at_s = e.restart_at_s;
    d.restart_down_s = e.restart_down_s;
    d.restart_initialization = e.restart_initialization;
    d.p_G_in_W_m = e.p_G_in_W_m;
    d.R_W_G = Eigen::Quaterniond(e.q_W_G_xyzw[3], e.q_W_G_xyzw[0], e.q_W_G_xyzw[1], e.q_W_G_xyzw[2])
                  .normalized()
                  .toRotationMatrix();
    if (!e.sensor_preset.empty()) {
      const Status status =
          config::LoadSensorPreset(Resolve(folder, e.sensor_preset), &d.lidar, &d.imu);
      if (!status.ok()) return file.KeyError(key + ".sensor_preset", status.message());
    }
    SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".lidar", &d.lidar));
    SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".imu", &d.imu));
    d.odometry = DefaultOdometryOptions(d.lidar, d.imu);
    SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".odometry", &d.odometry));
    SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".teammate", &d.teammate));
    SWARMLIO_RETURN_IF_ERROR(file.Read(key + ".swarm", &d.swarm));
    d.bag.point_time_unit = file.HasKey(key + ".bag_topics.point_time_unit")
                                ? d.bag.point_time_unit
                                : d.lidar.timestamp_unit;
    if (!file.HasKey(key + ".bag_topics.spinning_lidar")) {
      d.bag.spinning_lidar = d.lidar.type == LidarType::kSpinning;
    }
    out.drones.push_back(std::move(d));
  }
  *manifest = std::move(out);
  return Status::Ok();
}

Status LoadManifest(const std::string& path, SwarmManifest* manifest) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open the manifest");
  std::ostringstream text;
  text << in.rdbuf();
  // Relative paths in the manifest resolve against its folder.
  return ParseManifest(text.str(), path, manifest);
}

Status ManifestFromBags(const std::vector<std::string>& bags, const std::string& sensor_preset,
                        const std::vector<std::string>& names, SwarmManifest* manifest) {
  if (bags.empty()) return Status::InvalidArgument("no bags given");
  if (!names.empty() && names.size() != bags.size()) {
    return Status::InvalidArgument(std::to_string(bags.size()) + " bags but " +
                                   std::to_string(names.size()) + " names");
  }
  SwarmManifest out;
  out.name = "replay";
  std::set<std::string> seen;
  for (size_t i = 0; i < bags.size(); ++i) {
    DroneInput d;
    d.name = names.empty() ? "uav" + std::to_string(i + 1) : names[i];
    if (d.name.empty() || !seen.insert(d.name).second) {
      return Status::InvalidArgument("drone name '" + d.name + "' is empty or repeated");
    }
    d.bag_path = bags[i];
    if (!sensor_preset.empty()) {
      SWARMLIO_RETURN_IF_ERROR(config::LoadSensorPreset(sensor_preset, &d.lidar, &d.imu));
    }
    d.odometry = DefaultOdometryOptions(d.lidar, d.imu);
    d.bag.point_time_unit = d.lidar.timestamp_unit;
    d.bag.spinning_lidar = d.lidar.type == LidarType::kSpinning;
    out.drones.push_back(std::move(d));
  }
  *manifest = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::driver
