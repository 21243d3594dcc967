#include "swarmlio/eval/rpe.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

namespace swarmlio::eval {

bool DeltaUnitFromString(const std::string& text, DeltaUnit* unit) {
  if (text == "f" || text == "frames") {
    *unit = DeltaUnit::kFrames;
  } else if (text == "m" || text == "meters" || text == "metres") {
    *unit = DeltaUnit::kMeters;
  } else {
    return false;
  }
  return true;
}

const char* DeltaUnitName(DeltaUnit unit) { return unit == DeltaUnit::kFrames ? "f" : "m"; }

namespace {

Status CheckDelta(double delta, DeltaUnit unit) {
  if (!std::isfinite(delta) || delta <= 0.0) {
    return Status::InvalidArgument("RPE: delta must be > 0, got " + std::to_string(delta));
  }
  if (unit == DeltaUnit::kFrames && delta != std::floor(delta)) {
    return Status::InvalidArgument("RPE: a delta in frames must be an integer, got " +
                                   std::to_string(delta));
  }
  return Status::Ok();
}

Status NoPair(double delta, DeltaUnit unit, size_t num_poses) {
  return Status::FailedPrecondition("RPE: delta = " + std::to_string(delta) + " " +
                                    DeltaUnitName(unit) + " gives no pose pair on " +
                                    std::to_string(num_poses) +
                                    " associated poses; use a smaller delta");
}

}  // namespace

Status RpeIdPairs(const Trajectory& poses,
                  double delta,
                  DeltaUnit unit,
                  std::vector<IdPair>* id_pairs) {
  SWARMLIO_RETURN_IF_ERROR(CheckDelta(delta, unit));
  std::vector<size_t> ids;
  if (unit == DeltaUnit::kFrames) {
    const size_t step = static_cast<size_t>(delta);
    for (size_t i = 0; i < poses.size(); i += step) ids.push_back(i);
  } else {
    double path_m = 0.0;
    for (size_t i = 0; i < poses.size(); ++i) {
      if (i > 0) path_m += (poses.T_G_b[i].translation() - poses.T_G_b[i - 1].translation()).norm();
      if (path_m >= delta) {
        ids.push_back(i);
        path_m = 0.0;
      }
    }
  }
  std::vector<IdPair> out;
  for (size_t k = 1; k < ids.size(); ++k) out.emplace_back(ids[k - 1], ids[k]);
  if (out.empty()) return NoPair(delta, unit, poses.size());
  *id_pairs = std::move(out);
  return Status::Ok();
}

Status RpeAllIdPairs(const Trajectory& poses,
                     double delta,
                     DeltaUnit unit,
                     double relative_tolerance,
                     std::vector<IdPair>* id_pairs) {
  SWARMLIO_RETURN_IF_ERROR(CheckDelta(delta, unit));
  if (!(relative_tolerance >= 0.0 && relative_tolerance < 1.0)) {
    return Status::InvalidArgument("RPE: the all-pairs relative tolerance must be in [0, 1), got " +
                                   std::to_string(relative_tolerance));
  }
  const size_t n = poses.size();
  std::vector<IdPair> out;
  if (unit == DeltaUnit::kFrames) {
    const size_t step = static_cast<size_t>(delta);
    for (size_t i = 0; i + step < n; ++i) out.emplace_back(i, i + step);
  } else {
    // path_m[k]: path length from pose 0 to pose k (non-decreasing).
    std::vector<double> path_m(n, 0.0);
    for (size_t k = 1; k < n; ++k) {
      path_m[k] = path_m[k - 1] +
                  (poses.T_G_b[k].translation() - poses.T_G_b[k - 1].translation()).norm();
    }
    const double tolerance_m = relative_tolerance * delta;
    for (size_t i = 0; i + 1 < n; ++i) {
      const double target = path_m[i] + delta;
      // First index at or beyond the target, then the nearer of it and the
      // last index before it (the smaller index on a tie; on a stretch of
      // equal path lengths, its first index).
      const auto begin = path_m.begin() + static_cast<std::ptrdiff_t>(i + 1);
      size_t j = static_cast<size_t>(std::lower_bound(begin, path_m.end(), target) -
                                     path_m.begin());
      size_t best = n;
      if (j < n) best = j;
      if (j > i + 1) {
        const double below = path_m[j - 1];
        if (best == n || target - below <= path_m[j] - target) {
          best = static_cast<size_t>(std::lower_bound(begin, path_m.end(), below) -
                                     path_m.begin());
        }
      }
      if (best < n && std::abs(path_m[best] - target) <= tolerance_m) out.emplace_back(i, best);
    }
  }
  if (out.empty()) return NoPair(delta, unit, n);
  *id_pairs = std::move(out);
  return Status::Ok();
}

Status ComputeRpe(const Trajectory& reference,
                  const Trajectory& estimate,
                  const RpeOptions& options,
                  RpeResult* result) {
  if (options.translation_in_world && options.relation != PoseRelation::kTranslation) {
    return Status::InvalidArgument(
        "RPE: the displacement error in the world frame is a translation (relation trans_part), "
        "got " + std::string(PoseRelationName(options.relation)));
  }
  RpeResult out;
  SWARMLIO_RETURN_IF_ERROR(
      AssociateTrajectories(reference, estimate, options.association, &out.associated));
  UmeyamaResult transform;
  SWARMLIO_RETURN_IF_ERROR(AlignTrajectory(out.associated.reference, out.associated.estimate,
                                           options.alignment, &out.aligned_estimate, &transform));
  const Trajectory& Q = out.associated.reference;
  const Trajectory& P = out.aligned_estimate;
  SWARMLIO_RETURN_IF_ERROR(
      options.all_pairs
          ? RpeAllIdPairs(P, options.delta, options.delta_unit,
                          options.all_pairs_relative_tolerance, &out.id_pairs)
          : RpeIdPairs(P, options.delta, options.delta_unit, &out.id_pairs));
  out.errors.reserve(out.id_pairs.size());
  for (const IdPair& pair : out.id_pairs) {
    if (options.translation_in_world) {
      const Eigen::Vector3d q_i_j =
          Q.T_G_b[pair.second].translation() - Q.T_G_b[pair.first].translation();
      const Eigen::Vector3d p_i_j =
          P.T_G_b[pair.second].translation() - P.T_G_b[pair.first].translation();
      out.errors.push_back((p_i_j - q_i_j).norm());
      continue;
    }
    const Eigen::Isometry3d Q_i_j = Q.T_G_b[pair.first].inverse() * Q.T_G_b[pair.second];
    const Eigen::Isometry3d P_i_j = P.T_G_b[pair.first].inverse() * P.T_G_b[pair.second];
    out.errors.push_back(PoseRelationError(Q_i_j.inverse() * P_i_j, options.relation));
  }
  SWARMLIO_RETURN_IF_ERROR(ComputeErrorStatistics(out.errors, &out.statistics).WithContext("RPE"));
  *result = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::eval
