#include "swarmlio/eval/ape.h"

namespace swarmlio::eval {

Status ComputeApe(const Trajectory& reference,
                  const Trajectory& estimate,
                  const ApeOptions& options,
                  ApeResult* result) {
  ApeResult out;
  SWARMLIO_RETURN_IF_ERROR(
      AssociateTrajectories(reference, estimate, options.association, &out.associated));
  SWARMLIO_RETURN_IF_ERROR(AlignTrajectory(out.associated.reference, out.associated.estimate,
                                           options.alignment, &out.aligned_estimate,
                                           &out.alignment_transform));
  const Trajectory& Q = out.associated.reference;
  const Trajectory& P = out.aligned_estimate;
  out.errors.reserve(Q.size());
  for (size_t i = 0; i < Q.size(); ++i) {
    if (options.relation == PoseRelation::kTranslation) {
      out.errors.push_back((P.T_G_b[i].translation() - Q.T_G_b[i].translation()).norm());
    } else {
      const Eigen::Isometry3d E = Q.T_G_b[i].inverse() * P.T_G_b[i];
      out.errors.push_back(PoseRelationError(E, options.relation));
    }
  }
  SWARMLIO_RETURN_IF_ERROR(ComputeErrorStatistics(out.errors, &out.statistics).WithContext("APE"));
  *result = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::eval
