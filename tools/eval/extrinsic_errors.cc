#include "extrinsic_errors.h"

#include "swarmlio/eval/trajectory_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace swarmlio::tools {
namespace {

int IndexOf(const driver::SwarmManifest& manifest, const std::string& name) {
  for (size_t i = 0; i < manifest.drones.size(); ++i) {
    if (manifest.drones[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

Status EvaluateExtrinsicErrors(const std::string& csv_path,
                               const driver::SwarmManifest& manifest,
                               const std::string& observer,
                               const std::map<std::string, double>& origins,
                               std::vector<ExtrinsicErrorRow>* rows) {
  rows->clear();
  const int i = IndexOf(manifest, observer);
  if (i < 0) return Status::NotFound("observer '" + observer + "' is not a drone of the manifest");
  // Each drone's global frame in the simulation world.
  std::vector<Eigen::Isometry3d> T_W_Gs;
  for (const driver::DroneInput& d : manifest.drones) T_W_Gs.push_back(d.T_W_G());
  for (const auto& [name, stamp_s] : origins) {
    const int k = IndexOf(manifest, name);
    if (k < 0) return Status::NotFound("origin for '" + name + "': not a drone of the manifest");
    const driver::DroneInput& d = manifest.drones[static_cast<size_t>(k)];
    if (d.ground_truth_path.empty()) {
      return Status::FailedPrecondition(name + ": an origin needs its ground truth file");
    }
    eval::Trajectory truth;
    SWARMLIO_RETURN_IF_ERROR(
        eval::ReadTumTrajectory(d.ground_truth_path, eval::TrajectoryReadOptions(), &truth));
    Eigen::Isometry3d T_G_b;
    if (!truth.PoseAt(stamp_s, std::numeric_limits<double>::infinity(), &T_G_b)) {
      return Status::OutOfRange(name + " origin: stamp " + std::to_string(stamp_s) +
                                " s is outside the ground truth");
    }
    T_W_Gs[static_cast<size_t>(k)] = T_W_Gs[static_cast<size_t>(k)] * T_G_b;
  }
  std::ifstream in(csv_path);
  if (!in) return Status::IoError(csv_path + ": cannot open");
  std::string line;
  int line_number = 0;
  const auto where = [&]() { return csv_path + ":" + std::to_string(line_number) + ": "; };
  if (!std::getline(in, line) || line.rfind("stamp_s,teammate,qx,qy,qz,qw,x,y,z", 0) != 0) {
    return Status::DataLoss(csv_path + ": not an extrinsics CSV (header stamp_s,teammate,qx,...)");
  }
  ++line_number;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) fields.push_back(field);
    if (fields.size() < 9) return Status::DataLoss(where() + "fewer than 9 fields");
    double v[8];
    try {
      v[0] = std::stod(fields[0]);
      for (int k = 0; k < 7; ++k) v[k + 1] = std::stod(fields[static_cast<size_t>(k + 2)]);
    } catch (const std::exception&) {
      return Status::DataLoss(where() + "a number does not parse");
    }
    const int j = IndexOf(manifest, fields[1]);
    if (j < 0) return Status::NotFound(where() + "teammate '" + fields[1] + "' is not in the manifest");
    const Eigen::Quaterniond q(v[4], v[1], v[2], v[3]);
    const Eigen::Vector3d p(v[5], v[6], v[7]);
    if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3 || !p.allFinite()) {
      return Status::DataLoss(where() + "not a finite pose with a unit quaternion");
    }
    const Eigen::Isometry3d T_true =
        T_W_Gs[static_cast<size_t>(i)].inverse() * T_W_Gs[static_cast<size_t>(j)];
    const double e_m = (p - T_true.translation()).norm();
    const double e_deg = Eigen::AngleAxisd(T_true.linear().transpose() *
                                           q.normalized().toRotationMatrix()).angle() * 180.0 / M_PI;
    ExtrinsicErrorRow* row = nullptr;
    for (ExtrinsicErrorRow& r : *rows) {
      if (r.teammate == fields[1]) row = &r;
    }
    if (row == nullptr) {
      rows->push_back(ExtrinsicErrorRow());
      row = &rows->back();
      row->teammate = fields[1];
      row->first_s = v[0];
    }
    ++row->estimates;
    row->last_s = v[0];
    row->end_m = e_m;
    row->end_deg = e_deg;
    row->max_m = std::max(row->max_m, e_m);
    row->max_deg = std::max(row->max_deg, e_deg);
  }
  return Status::Ok();
}

}  // namespace swarmlio::tools
