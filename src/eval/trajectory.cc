#include "swarmlio/eval/trajectory.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace swarmlio::eval {

Eigen::Matrix3Xd Trajectory::Positions() const {
  Eigen::Matrix3Xd positions(3, static_cast<Eigen::Index>(T_G_b.size()));
  for (size_t i = 0; i < T_G_b.size(); ++i) {
    positions.col(static_cast<Eigen::Index>(i)) = T_G_b[i].translation();
  }
  return positions;
}

bool Trajectory::PoseAt(double stamp_s, double max_gap_s, Eigen::Isometry3d* T) const {
  if (size() < 2 || stamps_s.size() != size() || !(stamp_s >= stamps_s.front()) ||
      !(stamp_s <= stamps_s.back())) {
    return false;
  }
  const auto it = std::lower_bound(stamps_s.begin(), stamps_s.end(), stamp_s);
  const size_t k = std::max<size_t>(1, static_cast<size_t>(it - stamps_s.begin()));
  const double t0 = stamps_s[k - 1], t1 = stamps_s[k];
  if (t1 - t0 > max_gap_s) return false;
  const double a = t1 > t0 ? (stamp_s - t0) / (t1 - t0) : 0.0;
  const Eigen::Quaterniond q0(T_G_b[k - 1].linear()), q1(T_G_b[k].linear());
  *T = Eigen::Isometry3d::Identity();
  T->linear() = q0.slerp(a, q1).toRotationMatrix();
  T->translation() = (1.0 - a) * T_G_b[k - 1].translation() + a * T_G_b[k].translation();
  return true;
}

Trajectory Trajectory::Select(const std::vector<size_t>& ids) const {
  Trajectory out;
  out.T_G_b.reserve(ids.size());
  if (has_stamps()) out.stamps_s.reserve(ids.size());
  for (const size_t id : ids) {
    out.T_G_b.push_back(T_G_b.at(id));
    if (has_stamps()) out.stamps_s.push_back(stamps_s.at(id));
  }
  return out;
}

Trajectory TrajectoryFromPoses(const std::vector<PoseStamped>& poses) {
  Trajectory out;
  out.stamps_s.reserve(poses.size());
  out.T_G_b.reserve(poses.size());
  for (const PoseStamped& pose : poses) {
    Eigen::Isometry3d T_G_b = Eigen::Isometry3d::Identity();
    T_G_b.linear() = pose.q_G_b.normalized().toRotationMatrix();
    T_G_b.translation() = pose.p_b_in_G;
    out.stamps_s.push_back(ToSeconds(pose.stamp_ns));
    out.T_G_b.push_back(T_G_b);
  }
  return out;
}

Status ValidateTrajectory(const Trajectory& trajectory, const std::string& name) {
  if (trajectory.has_stamps() && trajectory.stamps_s.size() != trajectory.T_G_b.size()) {
    return Status::InvalidArgument(name + ": " + std::to_string(trajectory.stamps_s.size()) +
                                   " stamps for " + std::to_string(trajectory.T_G_b.size()) +
                                   " poses");
  }
  for (size_t i = 0; i < trajectory.stamps_s.size(); ++i) {
    const double stamp_s = trajectory.stamps_s[i];
    if (!std::isfinite(stamp_s)) {
      return Status::InvalidArgument(name + ": pose " + std::to_string(i) +
                                     " has a non-finite stamp");
    }
    if (i > 0 && stamp_s < trajectory.stamps_s[i - 1]) {
      return Status::InvalidArgument(name + ": stamps decrease at pose " + std::to_string(i));
    }
  }
  for (size_t i = 0; i < trajectory.T_G_b.size(); ++i) {
    const Eigen::Isometry3d& T = trajectory.T_G_b[i];
    if (!T.matrix().allFinite()) {
      return Status::InvalidArgument(name + ": pose " + std::to_string(i) + " is not finite");
    }
    const Eigen::Matrix3d R = T.linear();
    const double orthonormality_error =
        (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (orthonormality_error > kMaxOrthonormalityError || R.determinant() <= 0.0) {
      return Status::InvalidArgument(name + ": pose " + std::to_string(i) +
                                     " has a rotation block that is not a rotation");
    }
  }
  return Status::Ok();
}

}  // namespace swarmlio::eval
