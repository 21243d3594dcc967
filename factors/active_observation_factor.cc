#include "factors/active_observation_factor.h"

#include "factors/observation_factor_util.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
ActiveObservationFactor::ActiveObservationFactor(const Eigen::Vector3d& p_bj_in_bi,
                                                 const Eigen::Vector3d& p_bj_in_Gj,
                                                 const Eigen::Matrix3d& Sigma_obs,
                                                 const Eigen::Matrix3d& Sigma_p_bj_in_Gj,
                                                 const Eigen::Matrix3d& R_Gi_bi,
                                                 const Eigen::Matrix3d& R_Gi_Gj)
    : p_bj_in_bi_(p_bj_in_bi), p_bj_in_Gj_(p_bj_in_Gj) {
  const Eigen::Matrix3d A = R_Gi_bi.transpose() * R_Gi_Gj;
  const Eigen::Matrix3d S = Sigma_obs + A * Sigma_p_bj_in_Gj * A.transpose();
  covariance_ = 0.5 * (S + S.transpose());
  sqrt_information_ = observation_factor::SqrtInformation(covariance_, "active observation");
}

Eigen::Vector3d ActiveObservationFactor::Predict(const EgoState& ego,
                                                 const GlobalExtrinsic& extrinsic) const {
  const Eigen::Matrix3d R_Gi_bi = so3::RotationOf(ego.q_G_b);
  const Eigen::Vector3d p_bj_in_Gi =
      so3::RotationOf(extrinsic.q_Ga_Gb) * p_bj_in_Gj_ + extrinsic.p_Gb_in_Ga;
  return R_Gi_bi.transpose() * (p_bj_in_Gi - ego.p_b_in_G);
}

Eigen::Vector3d ActiveObservationFactor::Residual(const EgoState& ego,
                                                  const GlobalExtrinsic& extrinsic) const {
  return sqrt_information_ * (Predict(ego, extrinsic) - p_bj_in_bi_);
}

void ActiveObservationFactor::TangentJacobian(
    const EgoState& ego,
    const GlobalExtrinsic& extrinsic,
    Eigen::Matrix<double, 3, EgoState::kTangentSize>* J_ego,
    Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize>* J_ext) const {
  const Eigen::Matrix3d Rt_Gi_bi = so3::RotationOf(ego.q_G_b).transpose();
  if (J_ego != nullptr) {
    J_ego->setZero();
    J_ego->block<3, 3>(0, ErrorStateLayout::kRotation.offset) =
        sqrt_information_ * so3::Hat(Predict(ego, extrinsic));
    J_ego->block<3, 3>(0, ErrorStateLayout::kPosition.offset) = -sqrt_information_ * Rt_Gi_bi;
  }
  if (J_ext != nullptr) {
    const Eigen::Matrix3d W_Rt = sqrt_information_ * Rt_Gi_bi;
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateRotationOffset) =
        -W_Rt * so3::RotationOf(extrinsic.q_Ga_Gb) * so3::Hat(p_bj_in_Gj_);
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateTranslationOffset) = W_Rt;
  }
}

bool ActiveObservationFactor::Evaluate(double const* const* parameters,
                                       double* residuals,
                                       double** jacobians) const {
  return observation_factor::Evaluate(*this, parameters, residuals, jacobians);
}

}  // namespace swarmlio
