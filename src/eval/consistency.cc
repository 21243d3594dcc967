#include "swarmlio/eval/consistency.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "swarmlio/math/so3.h"
#include "swarmlio/math/umeyama.h"

namespace swarmlio::eval {
namespace {

// The poses with integer stamps and quaternions: the ground truth is
// interpolated in integer nanoseconds (exact weights), as the bag's poses are.
std::vector<PoseStamped> ToPoses(const Trajectory& t) {
  std::vector<PoseStamped> out;
  out.reserve(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    PoseStamped p;
    p.stamp_ns = static_cast<int64_t>(std::llround(t.stamps_s[i] * 1e9));
    p.q_G_b = Eigen::Quaterniond(t.T_G_b[i].linear());
    p.p_b_in_G = t.T_G_b[i].translation();
    out.push_back(p);
  }
  return out;
}

// Ground-truth pose at `stamp_ns` interpolated from `gt` (sorted by stamp).
// False when `stamp_ns` is outside `gt` or the bracketing poses are more
// than max_gap_ns apart.
bool InterpolatePose(const std::vector<PoseStamped>& gt,
                     int64_t stamp_ns,
                     int64_t max_gap_ns,
                     PoseStamped* pose) {
  const auto it = std::lower_bound(gt.begin(), gt.end(), stamp_ns,
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

}  // namespace

std::string FrameCheck::Summary() const {
  std::ostringstream os;
  os.precision(3);
  if (same_frame) {
    os << "ground truth in G";
    if (declared) os << " (declared)";
    if (compared) {
      os << (declared ? ", " : " (") << "first pose within " << position_offset_m << " m, "
         << rotation_offset_deg << " deg" << (declared ? "" : ")");
    }
    return os.str();
  }
  os << "ground truth in another frame: aligned by first pose and SE(3)";
  if (declared) os << " (declared)";
  if (compared) {
    os << (declared ? ", " : " (") << "first pose " << position_offset_m << " m, "
       << rotation_offset_deg << " deg from the estimate's" << (declared ? "" : ")");
  }
  return os.str();
}

Status CheckGroundTruthFrame(const Trajectory& estimate,
                             const Trajectory& reference,
                             GroundTruthFrame declared,
                             const FrameCheckOptions& options,
                             FrameCheck* check) {
  const std::vector<PoseStamped> gt = ToPoses(reference);
  FrameCheck c;
  c.declared = declared != GroundTruthFrame::kAuto;
  const int64_t max_gap_ns = static_cast<int64_t>(std::llround(options.max_gt_gap_s * 1e9));
  for (const PoseStamped& r : ToPoses(estimate)) {
    PoseStamped truth;
    if (!InterpolatePose(gt, r.stamp_ns, max_gap_ns, &truth)) continue;
    c.compared = true;
    c.stamp_ns = r.stamp_ns;
    c.position_offset_m = (truth.p_b_in_G - r.p_b_in_G).norm();
    c.rotation_offset_deg =
        so3::Log(truth.q_G_b.normalized().conjugate() * r.q_G_b.normalized()).norm() * 180.0 / M_PI;
    break;
  }
  if (declared == GroundTruthFrame::kG) {
    c.same_frame = true;
  } else if (declared == GroundTruthFrame::kAuto) {
    if (!c.compared) {
      return Status::FailedPrecondition("no estimated pose overlaps the ground truth");
    }
    c.same_frame = c.position_offset_m <= options.max_position_offset_m &&
                   c.rotation_offset_deg <= options.max_rotation_offset_deg;
  }
  *check = c;
  return Status::Ok();
}

Status AlignGroundTruthByFirstPose(const Trajectory& estimate,
                                   const Trajectory& reference,
                                   const FrameCheck& check,
                                   double max_gt_gap_s,
                                   Trajectory* aligned) {
  if (!check.compared) {
    return Status::FailedPrecondition("no estimated pose overlaps the ground truth");
  }
  const std::vector<PoseStamped> poses = ToPoses(estimate);
  const std::vector<PoseStamped> gt = ToPoses(reference);
  const PoseStamped* first = nullptr;
  for (const PoseStamped& r : poses) {
    if (r.stamp_ns == check.stamp_ns) {
      first = &r;
      break;
    }
  }
  PoseStamped truth;
  const int64_t max_gap_ns = static_cast<int64_t>(std::llround(max_gt_gap_s * 1e9));
  if (first == nullptr || !InterpolatePose(gt, check.stamp_ns, max_gap_ns, &truth)) {
    return Status::FailedPrecondition(
        "the first-pose stamp of the frame check is not in the "
        "estimate or the ground truth");
  }
  // T_G_W = T_G_b(t0) * T_W_b(t0)^-1.
  const Eigen::Quaterniond q_G_W = first->q_G_b.normalized() * truth.q_G_b.normalized().conjugate();
  const Eigen::Vector3d p_W_in_G = first->p_b_in_G - q_G_W * truth.p_b_in_G;
  Trajectory out;
  out.stamps_s = reference.stamps_s;
  out.T_G_b.reserve(gt.size());
  for (const PoseStamped& p : gt) {
    Eigen::Isometry3d T_G_b = Eigen::Isometry3d::Identity();
    T_G_b.linear() = (q_G_W * p.q_G_b.normalized()).normalized().toRotationMatrix();
    T_G_b.translation() = q_G_W * p.p_b_in_G + p_W_in_G;
    out.T_G_b.push_back(T_G_b);
  }
  *aligned = std::move(out);
  return Status::Ok();
}

Status EvaluateConsistency(const CovariantTrajectory& estimate,
                           const Trajectory& reference,
                           double max_gt_gap_s,
                           ConsistencyStats* stats) {
  if (estimate.position_covariances.size() != estimate.poses.size()) {
    return Status::InvalidArgument("consistency: one position covariance per pose expected");
  }
  const bool map_covariances = !estimate.map_position_covariances.empty();
  if (map_covariances && estimate.map_position_covariances.size() != estimate.poses.size()) {
    return Status::InvalidArgument("consistency: one map position covariance per pose expected");
  }
  const std::vector<PoseStamped> poses = ToPoses(estimate.poses);
  const std::vector<PoseStamped> gt = ToPoses(reference);
  ConsistencyStats s;
  double sum_sq = 0.0, sum_nees = 0.0, sum_rot_sq = 0.0;
  const int64_t max_gap_ns = static_cast<int64_t>(std::llround(max_gt_gap_s * 1e9));
  // Kept for the gauge-aligned NEES: position pairs and the factors of the
  // covariances relative to the estimator's own map.
  std::vector<Eigen::Vector3d> truth_positions, estimated_positions;
  std::vector<Eigen::LDLT<Eigen::Matrix3d>> factors;
  for (size_t i = 0; i < poses.size(); ++i) {
    const PoseStamped& r = poses[i];
    PoseStamped truth;
    if (!InterpolatePose(gt, r.stamp_ns, max_gap_ns, &truth)) continue;
    const Eigen::Vector3d e = r.p_b_in_G - truth.p_b_in_G;
    const Eigen::Matrix3d& P_pp = estimate.position_covariances[i];
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(P_pp);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
    const Eigen::LDLT<Eigen::Matrix3d> map_ldlt =
        map_covariances ? Eigen::LDLT<Eigen::Matrix3d>(estimate.map_position_covariances[i]) : ldlt;
    if (map_ldlt.info() != Eigen::Success || !map_ldlt.isPositive()) continue;
    const double nees = e.dot(ldlt.solve(e));
    const double rot_deg = so3::Log(truth.q_G_b.conjugate() * r.q_G_b).norm() * 180.0 / M_PI;
    ++s.num_poses;
    sum_sq += e.squaredNorm();
    sum_nees += nees;
    sum_rot_sq += rot_deg * rot_deg;
    s.position_max_m = std::max(s.position_max_m, e.norm());
    truth_positions.push_back(truth.p_b_in_G);
    estimated_positions.push_back(r.p_b_in_G);
    factors.push_back(map_ldlt);
  }
  if (s.num_poses == 0) {
    return Status::FailedPrecondition("no estimated pose overlaps the ground truth");
  }
  s.position_rmse_m = std::sqrt(sum_sq / s.num_poses);
  s.mean_position_nees = sum_nees / s.num_poses;
  s.rotation_rmse_deg = std::sqrt(sum_rot_sq / s.num_poses);

  // Gauge-aligned NEES: the ground truth rotated about the first pose onto the
  // estimate (the first positions coincide in G), fitted to the displacements
  // from the first pose. Refused when they do not fix a rotation.
  s.mean_position_nees_aligned = std::numeric_limits<double>::quiet_NaN();
  const int n = s.num_poses;
  Eigen::Matrix3Xd truth_moves(3, n), estimated_moves(3, n);
  for (int k = 0; k < n; ++k) {
    truth_moves.col(k) = truth_positions[k] - truth_positions[0];
    estimated_moves.col(k) = estimated_positions[k] - estimated_positions[0];
  }
  UmeyamaOptions about_start;
  about_start.with_translation = false;
  about_start.min_second_singular_value_m2 = 0.01;
  UmeyamaResult gauge;
  if (AlignUmeyama(truth_moves, estimated_moves, about_start, &gauge).ok()) {
    double sum_aligned = 0.0;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d e = estimated_moves.col(k) - gauge.R_dst_src * truth_moves.col(k);
      sum_aligned += e.dot(factors[k].solve(e));
    }
    s.mean_position_nees_aligned = sum_aligned / n;
    s.gauge_rotation_deg = so3::Log(Eigen::Quaterniond(gauge.R_dst_src)).norm() * 180.0 / M_PI;
  }
  *stats = s;
  return Status::Ok();
}

}  // namespace swarmlio::eval
