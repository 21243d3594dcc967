#include "live_outputs.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>

#include "swarmlio/replay/dropped_scans.h"

namespace swarmlio::tools {
namespace {

Status OpenFile(const std::string& path, const char* header, std::FILE** file) {
  *file = std::fopen(path.c_str(), "w");
  if (*file == nullptr) return Status::IoError(path + ": " + std::strerror(errno));
  if (std::fputs(header, *file) < 0) return Status::IoError(path + ": write failed");
  return Status::Ok();
}

}  // namespace

Status LiveOutputs::Open(const std::string& dir, const std::string& name, bool imu_odometry,
                         const std::vector<std::string>& drone_names,
                         std::unique_ptr<LiveOutputs>* outputs) {
  std::unique_ptr<LiveOutputs> o(new LiveOutputs());
  o->name_ = name;
  o->drone_names_ = drone_names;
  const std::filesystem::path base(dir);
  o->extrinsics_path_ = (base / (name + "_extrinsics.csv")).string();
  o->identifications_path_ = (base / (name + "_identifications.csv")).string();
  SWARMLIO_RETURN_IF_ERROR(OpenFile(
      o->extrinsics_path_,
      "stamp_s,teammate,qx,qy,qz,qw,x,y,z,var_rx,var_ry,var_rz,var_x,var_y,var_z,active,passive\n",
      &o->extrinsics_));
  SWARMLIO_RETURN_IF_ERROR(
      OpenFile(o->identifications_path_,
               "observer,teammate,stamp_s,since_first_scan_s,method,mean_residual_m\n",
               &o->identifications_));
  o->dropped_path_ = (base / (name + "_dropped_scans.txt")).string();
  SWARMLIO_RETURN_IF_ERROR(OpenFile(o->dropped_path_, replay::kDroppedScansHeader, &o->dropped_));
  o->tum_path_ = (base / (name + "_tum.txt")).string();
  o->timing_path_ = (base / (name + "_timing.csv")).string();
  SWARMLIO_RETURN_IF_ERROR(
      OpenFile(o->tum_path_, "# timestamp tx ty tz qx qy qz qw\n", &o->tum_));
  SWARMLIO_RETURN_IF_ERROR(OpenFile(
      o->timing_path_,
      "stamp_s,dropped,updated,raw_points,points,correspondences,iterations,degenerate,"
      "teammates,active_observations,passive_observations,total_ms,latency_ms,"
      "held_by_initialization\n",
      &o->timing_));
  if (imu_odometry) {
    o->imu_path_ = (base / (name + "_imu_odom.csv")).string();
    SWARMLIO_RETURN_IF_ERROR(OpenFile(
        o->imu_path_, "stamp_s,x_m,y_m,z_m,qx,qy,qz,qw,vx_m_s,vy_m_s,vz_m_s,wx_rad_s,wy_rad_s,wz_rad_s\n",
        &o->imu_));
  }
  *outputs = std::move(o);
  return Status::Ok();
}

LiveOutputs::~LiveOutputs() { (void)Close(); }

void LiveOutputs::Check(bool ok, const std::string& path) {
  if (!ok && error_.empty()) error_ = path + ": write failed: " + std::strerror(errno);
}

std::string LiveOutputs::DroneName(int id) const {
  if (id >= 0 && static_cast<size_t>(id) < drone_names_.size()) return drone_names_[id];
  return "id" + std::to_string(id);
}

void LiveOutputs::OnScan(const swarm::DroneOutput& o, const live::ScanLatency& latency) {
  const EgoState& x = o.ego.state;
  const double t_s = ToSeconds(o.ego.stamp_ns);
  if (first_scan_s_ < 0.0) first_scan_s_ = t_s;
  for (const swarm::IdentificationEvent& e : o.identifications) {
    Check(std::fprintf(identifications_, "%s,%s,%.6f,%.6f,%s,%.6g\n", name_.c_str(),
                       DroneName(e.drone_id).c_str(), ToSeconds(e.stamp_ns),
                       ToSeconds(e.stamp_ns) - first_scan_s_, e.method.c_str(),
                       e.mean_residual_m) > 0,
          identifications_path_);
  }
  for (const swarm::TeammateEstimate& e : o.teammates) {
    const Eigen::Quaterniond& q = e.T_Gi_Gj.q_Ga_Gb;
    const Eigen::Vector3d& p = e.T_Gi_Gj.p_Gb_in_Ga;
    const auto& C = e.extrinsic_covariance;
    Check(std::fprintf(extrinsics_,
                       "%.9f,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d\n",
                       t_s, DroneName(e.drone_id).c_str(), q.x(), q.y(), q.z(), q.w(), p.x(),
                       p.y(), p.z(), C(0, 0), C(1, 1), C(2, 2), C(3, 3), C(4, 4), C(5, 5),
                       e.active_observations, e.passive_observations) > 0,
          extrinsics_path_);
  }
  Check(std::fprintf(tum_, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", t_s,
                     x.p_b_in_G.x(), x.p_b_in_G.y(), x.p_b_in_G.z(), x.q_G_b.x(), x.q_G_b.y(),
                     x.q_G_b.z(), x.q_G_b.w()) > 0,
        tum_path_);
  const double latency_ms = 1e-6 * static_cast<double>(latency.latency_ns());
  // A scan the in-flight initialization held has its delay, not the pipeline's.
  if (!o.ego.held_by_initialization) latencies_ms_.push_back(static_cast<float>(latency_ms));
  Check(std::fprintf(timing_, "%.9f,,%d,%d,%d,%d,%d,%d,%zu,%d,%d,%.3f,%.3f,%d\n", t_s,
                     o.ego.updated ? 1 : 0, o.ego.num_raw_points, o.ego.num_points,
                     o.ego.num_correspondences, o.ego.iterations, o.ego.degenerate ? 1 : 0,
                     o.teammates.size(), o.active_observations, o.passive_observations,
                     1e3 * o.ego.timings.total_s, latency_ms,
                     o.ego.held_by_initialization ? 1 : 0) > 0,
        timing_path_);
}

void LiveOutputs::OnScanDropped(int64_t scan_stamp_ns, live::ScanDropReason reason) {
  const char* why = reason == live::ScanDropReason::kQueueFull ? "queue" : "backlog";
  Check(std::fprintf(timing_, "%.9f,%s,,,,,,,,,,,,\n", ToSeconds(scan_stamp_ns), why) > 0,
        timing_path_);
  // Flushed at once: a re-run of a crashed process still leaves these out.
  Check(std::fprintf(dropped_, "%lld %s\n", static_cast<long long>(scan_stamp_ns), why) > 0 &&
            std::fflush(dropped_) == 0,
        dropped_path_);
}

void LiveOutputs::OnImuPose(const live::ImuRatePose& p) {
  if (imu_ == nullptr) return;
  const Eigen::Vector3d& w = p.angular_velocity_in_b_rad_s;
  Check(std::fprintf(imu_, "%.9f,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f\n",
                     ToSeconds(p.stamp_ns), p.p_b_in_G.x(), p.p_b_in_G.y(), p.p_b_in_G.z(),
                     p.q_G_b.x(), p.q_G_b.y(), p.q_G_b.z(), p.q_G_b.w(), p.v_b_in_G.x(),
                     p.v_b_in_G.y(), p.v_b_in_G.z(), w.x(), w.y(), w.z()) > 0,
        imu_path_);
}

Status LiveOutputs::Close() {
  for (auto [file, path] :
       {std::pair{&tum_, &tum_path_}, std::pair{&timing_, &timing_path_},
        std::pair{&imu_, &imu_path_}, std::pair{&extrinsics_, &extrinsics_path_},
        std::pair{&identifications_, &identifications_path_},
        std::pair{&dropped_, &dropped_path_}}) {
    if (*file == nullptr) continue;
    Check(std::fclose(*file) == 0, *path);
    *file = nullptr;
  }
  return error_.empty() ? Status::Ok() : Status::IoError(error_);
}

}  // namespace swarmlio::tools
