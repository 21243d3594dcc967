#include "swarmlio/eval/rpe.h"

#include <cmath>

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

Status RpeIdPairs(const Trajectory& poses,
                  double delta,
                  DeltaUnit unit,
                  std::vector<IdPair>* id_pairs) {
  if (!std::isfinite(delta) || delta <= 0.0) {
    return Status::InvalidArgument("RPE: delta must be > 0, got " + std::to_string(delta));
  }
  std::vector<size_t> ids;
  if (unit == DeltaUnit::kFrames) {
    if (delta != std::floor(delta)) {
      return Status::InvalidArgument("RPE: a delta in frames must be an integer, got " +
                                     std::to_string(delta));
    }
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
  if (out.empty()) {
    return Status::FailedPrecondition("RPE: delta = " + std::to_string(delta) + " " +
                                      DeltaUnitName(unit) + " gives no pose pair on " +
                                      std::to_string(poses.size()) +
                                      " associated poses; use a smaller delta");
  }
  *id_pairs = std::move(out);
  return Status::Ok();
}

Status ComputeRpe(const Trajectory& reference,
                  const Trajectory& estimate,
                  const RpeOptions& options,
                  RpeResult* result) {
  RpeResult out;
  SWARMLIO_RETURN_IF_ERROR(
      AssociateTrajectories(reference, estimate, options.association, &out.associated));
  UmeyamaResult transform;
  SWARMLIO_RETURN_IF_ERROR(AlignTrajectory(out.associated.reference, out.associated.estimate,
                                           options.alignment, &out.aligned_estimate, &transform));
  const Trajectory& Q = out.associated.reference;
  const Trajectory& P = out.aligned_estimate;
  SWARMLIO_RETURN_IF_ERROR(RpeIdPairs(P, options.delta, options.delta_unit, &out.id_pairs));
  out.errors.reserve(out.id_pairs.size());
  for (const IdPair& pair : out.id_pairs) {
    const Eigen::Isometry3d Q_i_j = Q.T_G_b[pair.first].inverse() * Q.T_G_b[pair.second];
    const Eigen::Isometry3d P_i_j = P.T_G_b[pair.first].inverse() * P.T_G_b[pair.second];
    out.errors.push_back(PoseRelationError(Q_i_j.inverse() * P_i_j, options.relation));
  }
  SWARMLIO_RETURN_IF_ERROR(ComputeErrorStatistics(out.errors, &out.statistics).WithContext("RPE"));
  *result = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::eval
