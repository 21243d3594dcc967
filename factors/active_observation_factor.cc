#include "factors/active_observation_factor.h"

#include <Eigen/Cholesky>

#include "factors/so3_manifold.h"
#include "swarmlio/common/check.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

using EgoJacobian = Eigen::Matrix<double, 3, EgoState::kAmbientSize, Eigen::RowMajor>;
using ExtrinsicJacobian = Eigen::Matrix<double, 3, GlobalExtrinsic::kAmbientSize, Eigen::RowMajor>;

Eigen::Matrix3d RotationOf(const Eigen::Quaterniond& q) {
  return q.normalized().toRotationMatrix();
}

}  // namespace

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
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance_);
  CHECK(covariance_.allFinite() && llt.info() == Eigen::Success)
      << "active observation covariance is not positive definite:\n"
      << covariance_;
  sqrt_information_ =
      llt.matrixL().solve(Eigen::Matrix3d::Identity()).triangularView<Eigen::Lower>();
}

Eigen::Vector3d ActiveObservationFactor::Predict(const EgoState& ego,
                                                 const GlobalExtrinsic& extrinsic) const {
  const Eigen::Matrix3d R_Gi_bi = RotationOf(ego.q_G_b);
  const Eigen::Vector3d p_bj_in_Gi =
      RotationOf(extrinsic.q_Gi_Gj) * p_bj_in_Gj_ + extrinsic.p_Gj_in_Gi;
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
  const Eigen::Matrix3d Rt_Gi_bi = RotationOf(ego.q_G_b).transpose();
  if (J_ego != nullptr) {
    J_ego->setZero();
    J_ego->block<3, 3>(0, ErrorStateLayout::kRotation.offset) =
        sqrt_information_ * so3::Hat(Predict(ego, extrinsic));
    J_ego->block<3, 3>(0, ErrorStateLayout::kPosition.offset) = -sqrt_information_ * Rt_Gi_bi;
  }
  if (J_ext != nullptr) {
    const Eigen::Matrix3d W_Rt = sqrt_information_ * Rt_Gi_bi;
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateRotationOffset) =
        -W_Rt * RotationOf(extrinsic.q_Gi_Gj) * so3::Hat(p_bj_in_Gj_);
    J_ext->block<3, 3>(0, ErrorStateLayout::kTeammateTranslationOffset) = W_Rt;
  }
}

bool ActiveObservationFactor::Evaluate(double const* const* parameters,
                                       double* residuals,
                                       double** jacobians) const {
  const EgoState ego = EgoState::FromParameters(parameters[0]);
  const GlobalExtrinsic extrinsic = GlobalExtrinsic::FromParameters(parameters[1]);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = Residual(ego, extrinsic);
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) return true;

  Eigen::Matrix<double, 3, EgoState::kTangentSize> J_ego;
  Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize> J_ext;
  TangentJacobian(ego, extrinsic, jacobians[0] != nullptr ? &J_ego : nullptr,
                  jacobians[1] != nullptr ? &J_ext : nullptr);
  if (jacobians[0] != nullptr) {
    Eigen::Map<EgoJacobian> J(jacobians[0]);
    J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<3>(J_ego.leftCols<3>(), parameters[0]);
    J.rightCols<15>() = J_ego.rightCols<15>();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<ExtrinsicJacobian> J(jacobians[1]);
    J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<3>(J_ext.leftCols<3>(), parameters[1]);
    J.rightCols<3>() = J_ext.rightCols<3>();
  }
  return true;
}

}  // namespace swarmlio
