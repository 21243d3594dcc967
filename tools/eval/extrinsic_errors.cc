#include "extrinsic_errors.h"

#include "swarmlio/eval/trajectory_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace swarmlio::tools {
namespace {

Eigen::Isometry3d T_W_G(const replay::DroneInput& d) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = d.R_W_G;
  T.translation() = d.p_G_in_W_m;
  return T;
}

// The body pose at `stamp_s` (position interpolated, attitude slerped).
Status PoseAt(const eval::Trajectory& t, double stamp_s, Eigen::Isometry3d* T) {
  if (t.size() < 2 || stamp_s < t.stamps_s.front() || stamp_s > t.stamps_s.back()) {
    return Status::OutOfRange("stamp " + std::to_string(stamp_s) + " s is outside the ground truth");
  }
  const auto it = std::lower_bound(t.stamps_s.begin(), t.stamps_s.end(), stamp_s);
  const size_t k = std::max<size_t>(1, static_cast<size_t>(it - t.stamps_s.begin()));
  const double t0 = t.stamps_s[k - 1], t1 = t.stamps_s[k];
  const double a = t1 > t0 ? (stamp_s - t0) / (t1 - t0) : 0.0;
  const Eigen::Quaterniond q0(t.T_G_b[k - 1].linear()), q1(t.T_G_b[k].linear());
  *T = Eigen::Isometry3d::Identity();
  T->linear() = q0.slerp(a, q1).toRotationMatrix();
  T->translation() = (1.0 - a) * t.T_G_b[k - 1].translation() + a * t.T_G_b[k].translation();
  return Status::Ok();
}

int IndexOf(const replay::SwarmManifest& manifest, const std::string& name) {
  for (size_t i = 0; i < manifest.drones.size(); ++i) {
    if (manifest.drones[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

Status EvaluateExtrinsicErrors(const std::string& csv_path,
                               const replay::SwarmManifest& manifest,
                               const std::string& observer,
                               const std::map<std::string, double>& origins,
                               std::vector<ExtrinsicErrorRow>* rows) {
  rows->clear();
  const int i = IndexOf(manifest, observer);
  if (i < 0) return Status::NotFound("observer '" + observer + "' is not a drone of the manifest");
  // Each drone's global frame in the simulation world.
  std::vector<Eigen::Isometry3d> T_W_Gs;
  for (const replay::DroneInput& d : manifest.drones) T_W_Gs.push_back(T_W_G(d));
  for (const auto& [name, stamp_s] : origins) {
    const int k = IndexOf(manifest, name);
    if (k < 0) return Status::NotFound("origin for '" + name + "': not a drone of the manifest");
    const replay::DroneInput& d = manifest.drones[static_cast<size_t>(k)];
    if (d.ground_truth_path.empty()) {
      return Status::FailedPrecondition(name + ": an origin needs its ground truth file");
    }
    eval::Trajectory truth;
    SWARMLIO_RETURN_IF_ERROR(
        eval::ReadTumTrajectory(d.ground_truth_path, eval::TrajectoryReadOptions(), &truth));
    Eigen::Isometry3d T_G_b;
    const Status s = PoseAt(truth, stamp_s, &T_G_b);
    if (!s.ok()) return s.WithContext(name + " origin");
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
