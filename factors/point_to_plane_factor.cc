#include "factors/point_to_plane_factor.h"

#include <cmath>

#include "factors/so3_manifold.h"
#include "swarmlio/common/check.h"

namespace swarmlio {

PointToPlaneFactor::PointToPlaneFactor(const std::vector<PlaneCorrespondence>* correspondences)
    : correspondences_(correspondences) {
  CHECK(correspondences_ != nullptr);
  mutable_parameter_block_sizes()->push_back(EgoState::kAmbientSize);
  SyncNumResiduals();
}

void PointToPlaneFactor::SyncNumResiduals() {
  set_num_residuals(static_cast<int>(correspondences_->size()));
}

bool PointToPlaneFactor::Evaluate(double const* const* parameters,
                                  double* residuals,
                                  double** jacobians) const {
  const std::vector<PlaneCorrespondence>& corr = *correspondences_;
  CHECK_EQ(static_cast<int>(corr.size()), num_residuals())
      << "correspondences changed without SyncNumResiduals()";
  const double* x = parameters[0];
  const Eigen::Quaterniond q_G_b(x[3], x[0], x[1], x[2]);
  const Eigen::Matrix3d R_G_b = q_G_b.normalized().toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> p_b_in_G(x + 4);

  const bool want_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
  Eigen::Matrix<double, 3, 4> minus_jacobian;
  if (want_jacobian) minus_jacobian = SO3Manifold::MinusJacobianAt(x);

  const int n = static_cast<int>(corr.size());
  for (int i = 0; i < n; ++i) {
    const PlaneCorrespondence& c = corr[i];
    const double s = std::sqrt(c.weight);
    residuals[i] = s * (c.normal_in_G.dot(R_G_b * c.p_in_b + p_b_in_G) + c.offset_m);
    if (!want_jacobian) continue;
    double* row = jacobians[0] + i * EgoState::kAmbientSize;
    const Eigen::Vector3d J_rot = s * c.p_in_b.cross(R_G_b.transpose() * c.normal_in_G);
    Eigen::Map<Eigen::Matrix<double, 1, EgoState::kAmbientSize>> J_row(row);
    J_row.head<4>() = J_rot.transpose() * minus_jacobian;
    J_row.segment<3>(4) = s * c.normal_in_G.transpose();
    J_row.tail<12>().setZero();
  }
  return true;
}

void PointToPlaneFactor::AccumulateNormalEquations(const EgoState& ego,
                                                   Eigen::Matrix<double, 6, 6>* HtH,
                                                   Eigen::Matrix<double, 6, 1>* Htz) const {
  const Eigen::Matrix3d R_G_b = ego.R_G_b();
  for (const PlaneCorrespondence& c : *correspondences_) {
    Eigen::Matrix<double, 6, 1> h;
    h.head<3>() = c.p_in_b.cross(R_G_b.transpose() * c.normal_in_G);
    h.tail<3>() = c.normal_in_G;
    const double z = c.normal_in_G.dot(R_G_b * c.p_in_b + ego.p_b_in_G) + c.offset_m;
    HtH->noalias() += c.weight * h * h.transpose();
    Htz->noalias() += c.weight * z * h;
  }
}

}  // namespace swarmlio
