#include "factors/passive_observation_factor.h"

#include "factors/observation_factor_util.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
PassiveObservationFactor::PassiveObservationFactor(const Eigen::Vector3d& p_bi_in_bj,
                                                   double dt,
                                                   const Eigen::Matrix3d& R_Gj_bj,
                                                   const Eigen::Vector3d& p_bj_in_Gj,
                                                   const Eigen::Matrix3d& Sigma_obs,
                                                   const Eigen::Matrix3d& Sigma_theta_bj,
                                                   const Eigen::Matrix3d& Sigma_p_bj_in_Gj,
                                                   const EgoState& ego_lin,
                                                   const GlobalExtrinsic& extrinsic_lin,
                                                   const ImuRetrodiction& retrodiction)
    : p_bi_in_bj_(p_bi_in_bj),
      dt_(dt),
      W_(retrodiction.weight_s2),
      accel_bias_lin_(ego_lin.accel_bias),
      R_Gj_bj_(R_Gj_bj),
      p_bj_in_Gj_(p_bj_in_Gj) {
  const Eigen::Matrix3d R0_T = ego_lin.R_G_b().transpose();
  u_ = R0_T * (retrodiction.weighted_acc_in_G - W_ * ego_lin.g_in_G);
  M_ = R0_T * retrodiction.weighted_R_G_b;
  const Eigen::Matrix3d h0_hat = so3::Hat(Predict(ego_lin, extrinsic_lin));
  const Eigen::Matrix3d S = Sigma_obs + h0_hat * Sigma_theta_bj * h0_hat.transpose() +
                            R_Gj_bj_.transpose() * Sigma_p_bj_in_Gj * R_Gj_bj_;
  covariance_ = 0.5 * (S + S.transpose());
  sqrt_information_ = observation_factor::SqrtInformation(covariance_, "passive observation");
}

Eigen::Vector3d PassiveObservationFactor::C(const EgoState& ego) const {
  return u_ + M_ * (accel_bias_lin_ - ego.accel_bias);
}

Eigen::Vector3d PassiveObservationFactor::EgoPositionInGj(const EgoState& ego,
                                                          const GlobalExtrinsic& extrinsic) const {
  const Eigen::Vector3d A = ego.R_G_b() * C(ego) + W_ * ego.g_in_G;
  return so3::RotationOf(extrinsic.q_Ga_Gb).transpose() *
         (ego.p_b_in_G + ego.v_b_in_G * dt_ + A - extrinsic.p_Gb_in_Ga);
}

Eigen::Vector3d PassiveObservationFactor::Predict(const EgoState& ego,
                                                  const GlobalExtrinsic& extrinsic) const {
  return R_Gj_bj_.transpose() * (EgoPositionInGj(ego, extrinsic) - p_bj_in_Gj_);
}

Eigen::Vector3d PassiveObservationFactor::Residual(const EgoState& ego,
                                                   const GlobalExtrinsic& extrinsic) const {
  return sqrt_information_ * (Predict(ego, extrinsic) - p_bi_in_bj_);
}

void PassiveObservationFactor::TangentJacobian(
    const EgoState& ego,
    const GlobalExtrinsic& extrinsic,
    Eigen::Matrix<double, 3, EgoState::kTangentSize>* J_ego,
    Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize>* J_ext) const {
  const Eigen::Matrix3d W_M =
      sqrt_information_ * R_Gj_bj_.transpose() * so3::RotationOf(extrinsic.q_Ga_Gb).transpose();
  if (J_ego != nullptr) {
    J_ego->setZero();
    J_ego->block<3, 3>(0, ErrorStateLayout::kPosition.offset) = W_M;
    J_ego->block<3, 3>(0, ErrorStateLayout::kVelocity.offset) = W_M * dt_;
    const Eigen::Matrix3d R = ego.R_G_b();
    J_ego->block<3, 3>(0, ErrorStateLayout::kRotation.offset) = -W_M * R * so3::Hat(C(ego));
    J_ego->block<3, 3>(0, ErrorStateLayout::kAccelBias.offset) = -W_M * R * M_;
    J_ego->block<3, 3>(0, ErrorStateLayout::kGravity.offset) = W_M * W_;
  }
  if (J_ext != nullptr) {
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateRotationOffset) =
        sqrt_information_ * R_Gj_bj_.transpose() * so3::Hat(EgoPositionInGj(ego, extrinsic));
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateTranslationOffset) = -W_M;
  }
}

bool PassiveObservationFactor::Evaluate(double const* const* parameters,
                                        double* residuals,
                                        double** jacobians) const {
  return observation_factor::Evaluate(*this, parameters, residuals, jacobians);
}

}  // namespace swarmlio
