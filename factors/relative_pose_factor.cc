#include "factors/relative_pose_factor.h"

#include <Eigen/Cholesky>

#include "factors/so3_manifold.h"
#include "swarmlio/common/check.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {

RelativePoseFactor::RelativePoseFactor(const Eigen::Quaterniond& q_a_b,
                                       const Eigen::Vector3d& p_b_in_a,
                                       const Matrix6& sqrt_information)
    : q_a_b_(q_a_b.normalized()), p_b_in_a_(p_b_in_a), sqrt_information_(sqrt_information) {
  CHECK(sqrt_information_.allFinite() && q_a_b_.coeffs().allFinite() && p_b_in_a_.allFinite())
      << "relative pose factor: non-finite measurement or square-root information";
}

RelativePoseFactor::Matrix6 RelativePoseFactor::SqrtInformationOfCovariance(
    const Matrix6& covariance) {
  const Matrix6 S = 0.5 * (covariance + covariance.transpose());
  const Eigen::LLT<Matrix6> llt(S);
  CHECK(S.allFinite() && llt.info() == Eigen::Success)
      << "relative pose covariance is not positive definite:\n"
      << S;
  return llt.matrixL().solve(Matrix6::Identity()).triangularView<Eigen::Lower>();
}

RelativePoseFactor::Vector6 RelativePoseFactor::Error(const EgoState& ego_a,
                                                      const EgoState& ego_b) const {
  const Eigen::Quaterniond q_G_a = ego_a.q_G_b.normalized();
  const Eigen::Quaterniond q_G_b = ego_b.q_G_b.normalized();
  Vector6 e;
  e.head<3>() = so3::Log(q_a_b_.conjugate() * q_G_a.conjugate() * q_G_b);
  e.tail<3>() = q_G_a.conjugate() * (ego_b.p_b_in_G - ego_a.p_b_in_G) - p_b_in_a_;
  return e;
}

RelativePoseFactor::Vector6 RelativePoseFactor::Residual(const EgoState& ego_a,
                                                         const EgoState& ego_b) const {
  return sqrt_information_ * Error(ego_a, ego_b);
}

void RelativePoseFactor::TangentJacobian(const EgoState& ego_a,
                                         const EgoState& ego_b,
                                         TangentJacobian6* J_a,
                                         TangentJacobian6* J_b) const {
  const Eigen::Matrix3d R_G_a = ego_a.q_G_b.normalized().toRotationMatrix();
  const Eigen::Matrix3d R_G_b = ego_b.q_G_b.normalized().toRotationMatrix();
  const Eigen::Vector3d e_rot = Error(ego_a, ego_b).head<3>();
  const Eigen::Matrix3d Jr_inv = so3::RightJacobianInverse(e_rot);
  const Eigen::Vector3d p_b_in_a = R_G_a.transpose() * (ego_b.p_b_in_G - ego_a.p_b_in_G);
  constexpr int kRot = ErrorStateLayout::kRotation.offset;
  constexpr int kPos = ErrorStateLayout::kPosition.offset;
  if (J_a != nullptr) {
    TangentJacobian6 H = TangentJacobian6::Zero();
    H.block<3, 3>(0, kRot) = -Jr_inv * R_G_b.transpose() * R_G_a;
    H.block<3, 3>(3, kRot) = so3::Hat(p_b_in_a);
    H.block<3, 3>(3, kPos) = -R_G_a.transpose();
    *J_a = sqrt_information_ * H;
  }
  if (J_b != nullptr) {
    TangentJacobian6 H = TangentJacobian6::Zero();
    H.block<3, 3>(0, kRot) = Jr_inv;
    H.block<3, 3>(3, kPos) = R_G_a.transpose();
    *J_b = sqrt_information_ * H;
  }
}

bool RelativePoseFactor::Evaluate(double const* const* parameters,
                                  double* residuals,
                                  double** jacobians) const {
  const EgoState ego_a = EgoState::FromParameters(parameters[0]);
  const EgoState ego_b = EgoState::FromParameters(parameters[1]);
  Eigen::Map<Vector6> r(residuals);
  r = Residual(ego_a, ego_b);
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) return true;
  TangentJacobian6 J_a;
  TangentJacobian6 J_b;
  TangentJacobian(ego_a, ego_b, &J_a, &J_b);
  using Ambient = Eigen::Matrix<double, 6, EgoState::kAmbientSize, Eigen::RowMajor>;
  const TangentJacobian6* tangent[2] = {&J_a, &J_b};
  for (int k = 0; k < 2; ++k) {
    if (jacobians[k] == nullptr) continue;
    Eigen::Map<Ambient> J(jacobians[k]);
    J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<6>(
        Eigen::Matrix<double, 6, 3>(tangent[k]->leftCols<3>()), parameters[k]);
    J.rightCols<15>() = tangent[k]->rightCols<15>();
  }
  return true;
}

}  // namespace swarmlio
