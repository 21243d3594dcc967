#include "swarmlio/replay/consistency.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "swarmlio/math/so3.h"

namespace swarmlio::replay {

bool InterpolatePose(const std::vector<PoseStamped>& gt, int64_t stamp_ns, int64_t max_gap_ns,
                     PoseStamped* pose) {
  const auto it = std::lower_bound(
      gt.begin(), gt.end(), stamp_ns,
      [](const PoseStamped& p, int64_t t) { return p.stamp_ns < t; });
  if (it == gt.end()) return false;
  if (it->stamp_ns == stamp_ns) {
    *pose = *it;
    return true;
  }
  if (it == gt.begin()) return false;
  const PoseStamped& b = *it;
  const PoseStamped& a = *(it - 1);
  if (b.stamp_ns - a.stamp_ns > max_gap_ns) return false;
  const double w =
      static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  pose->stamp_ns = stamp_ns;
  pose->frame_id = a.frame_id;
  pose->p_b_in_G = (1.0 - w) * a.p_b_in_G + w * b.p_b_in_G;
  pose->q_G_b = a.q_G_b.slerp(w, b.q_G_b);
  return true;
}

Status EvaluateConsistency(const std::vector<ScanRecord>& scans,
                           const std::vector<PoseStamped>& gt, double max_gt_gap_s,
                           ConsistencyStats* stats) {
  ConsistencyStats s;
  double sum_sq = 0.0, sum_nees = 0.0, sum_rot_sq = 0.0;
  const int64_t max_gap_ns = static_cast<int64_t>(std::llround(max_gt_gap_s * 1e9));
  for (const ScanRecord& r : scans) {
    if (!r.updated) continue;
    PoseStamped truth;
    if (!InterpolatePose(gt, r.stamp_ns, max_gap_ns, &truth)) continue;
    const Eigen::Vector3d e = r.state.p_b_in_G - truth.p_b_in_G;
    const Eigen::Matrix3d P_pp = r.pose_covariance.bottomRightCorner<3, 3>();
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(P_pp);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
    const double nees = e.dot(ldlt.solve(e));
    const double rot_deg =
        so3::Log(truth.q_G_b.conjugate() * r.state.q_G_b).norm() * 180.0 / M_PI;
    ++s.num_poses;
    sum_sq += e.squaredNorm();
    sum_nees += nees;
    sum_rot_sq += rot_deg * rot_deg;
    s.position_max_m = std::max(s.position_max_m, e.norm());
  }
  if (s.num_poses == 0) {
    return Status::FailedPrecondition("no estimated pose overlaps the ground truth");
  }
  s.position_rmse_m = std::sqrt(sum_sq / s.num_poses);
  s.mean_position_nees = sum_nees / s.num_poses;
  s.rotation_rmse_deg = std::sqrt(sum_rot_sq / s.num_poses);
  *stats = s;
  return Status::Ok();
}

}  // namespace swarmlio::replay
