#include "swarmlio/eval/alignment.h"

#include <string>

namespace swarmlio::eval {

bool AlignmentFromString(const std::string& text, Alignment* alignment) {
  if (text == "none") {
    *alignment = Alignment::kNone;
  } else if (text == "se3") {
    *alignment = Alignment::kSe3;
  } else if (text == "sim3") {
    *alignment = Alignment::kSim3;
  } else {
    return false;
  }
  return true;
}

const char* AlignmentName(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSe3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
  }
  return "?";
}

Trajectory TransformTrajectory(const Trajectory& trajectory, const UmeyamaResult& transform) {
  Trajectory out = trajectory;
  for (Eigen::Isometry3d& T_G_b : out.T_G_b) {
    const Eigen::Matrix3d R_G_b = transform.R_dst_src * T_G_b.linear();
    const Eigen::Vector3d p_b_in_G = transform.Apply(T_G_b.translation());
    T_G_b.linear() = R_G_b;
    T_G_b.translation() = p_b_in_G;
  }
  return out;
}

Status AlignTrajectory(const Trajectory& reference,
                       const Trajectory& estimate,
                       Alignment alignment,
                       Trajectory* aligned_estimate,
                       UmeyamaResult* transform) {
  if (reference.size() != estimate.size()) {
    return Status::InvalidArgument("alignment: " + std::to_string(reference.size()) +
                                   " reference poses but " + std::to_string(estimate.size()) +
                                   " estimated poses");
  }
  UmeyamaResult result;
  if (alignment == Alignment::kNone) {
    *aligned_estimate = estimate;
    *transform = result;
    return Status::Ok();
  }
  UmeyamaOptions options;
  options.with_scale = alignment == Alignment::kSim3;
  const Status status = AlignUmeyama(estimate.Positions(), reference.Positions(), options, &result);
  if (!status.ok()) {
    return status.WithContext(std::string("alignment (") + AlignmentName(alignment) + ")");
  }
  *aligned_estimate = TransformTrajectory(estimate, result);
  *transform = result;
  return Status::Ok();
}

}  // namespace swarmlio::eval
