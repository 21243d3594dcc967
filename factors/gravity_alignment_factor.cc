#include "factors/gravity_alignment_factor.h"

#include "factors/observation_factor_util.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {

GravityAlignmentFactor::GravityAlignmentFactor(const Eigen::Vector3d& g_in_Gj,
                                               const Eigen::Matrix3d& Sigma_g_in_Gj,
                                               double sigma_floor_m_s2,
                                               const Eigen::Matrix3d& R_Gi_Gj)
    : g_in_Gj_(g_in_Gj) {
  const Eigen::Matrix3d S = R_Gi_Gj * Sigma_g_in_Gj * R_Gi_Gj.transpose() +
                            sigma_floor_m_s2 * sigma_floor_m_s2 * Eigen::Matrix3d::Identity();
  covariance_ = 0.5 * (S + S.transpose());
  sqrt_information_ = observation_factor::SqrtInformation(covariance_, "gravity alignment");
}

Eigen::Vector3d GravityAlignmentFactor::Predict(const EgoState& ego,
                                                const GlobalExtrinsic& extrinsic) const {
  return extrinsic.q_Ga_Gb.normalized().toRotationMatrix() * g_in_Gj_ - ego.g_in_G;
}

Eigen::Vector3d GravityAlignmentFactor::Residual(const EgoState& ego,
                                                 const GlobalExtrinsic& extrinsic) const {
  return sqrt_information_ * Predict(ego, extrinsic);
}

void GravityAlignmentFactor::TangentJacobian(
    const EgoState&, const GlobalExtrinsic& extrinsic,
    Eigen::Matrix<double, 3, EgoState::kTangentSize>* J_ego,
    Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize>* J_ext) const {
  if (J_ego != nullptr) {
    J_ego->setZero();
    J_ego->block<3, 3>(0, ErrorStateLayout::kGravity.offset) = -sqrt_information_;
  }
  if (J_ext != nullptr) {
    J_ext->setZero();
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateRotationOffset) =
        -sqrt_information_ * extrinsic.q_Ga_Gb.normalized().toRotationMatrix() * so3::Hat(g_in_Gj_);
  }
}

bool GravityAlignmentFactor::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  return observation_factor::Evaluate(*this, parameters, residuals, jacobians);
}

}  // namespace swarmlio
