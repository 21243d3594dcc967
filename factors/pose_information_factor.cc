#include "factors/pose_information_factor.h"

#include <Eigen/Eigenvalues>

#include "factors/so3_manifold.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {

void PoseInformationFactor::Set(const Eigen::Matrix<double, 6, 6>& A,
                                const Eigen::Matrix<double, 6, 1>& b,
                                const Eigen::Quaterniond& q_G_b, const Eigen::Vector3d& p_b_in_G) {
  q_lin_ = q_G_b.normalized();
  p_lin_ = p_b_in_G;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(0.5 * (A + A.transpose()));
  const Eigen::Matrix<double, 6, 1>& l = eig.eigenvalues();
  const double threshold = 1e-12 * std::max(l.maxCoeff(), 0.0);
  W_.setZero();
  c_.setZero();
  for (int k = 0; k < 6; ++k) {
    if (!(l[k] > threshold) || l[k] <= 0.0) continue;
    const double s = std::sqrt(l[k]);
    W_.row(k) = s * eig.eigenvectors().col(k).transpose();
    c_[k] = eig.eigenvectors().col(k).dot(b) / s;
  }
}

Eigen::Matrix<double, 6, 1> PoseInformationFactor::Residual(const EgoState& ego) const {
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = so3::Log(q_lin_.conjugate() * ego.q_G_b.normalized());
  d.tail<3>() = ego.p_b_in_G - p_lin_;
  return W_ * d + c_;
}

bool PoseInformationFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const EgoState ego = EgoState::FromParameters(parameters[0]);
  const Eigen::Vector3d d_rot = so3::Log(q_lin_.conjugate() * ego.q_G_b.normalized());
  Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residuals);
  r = W_.leftCols<3>() * d_rot + W_.rightCols<3>() * (ego.p_b_in_G - p_lin_) + c_;
  if (jacobians == nullptr || jacobians[0] == nullptr) return true;
  Eigen::Map<Eigen::Matrix<double, 6, EgoState::kAmbientSize, Eigen::RowMajor>> J(jacobians[0]);
  const Eigen::Matrix<double, 6, 3> J_rot = W_.leftCols<3>() * so3::RightJacobianInverse(d_rot);
  J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<6>(J_rot, parameters[0]);
  J.block<6, 3>(0, 4) = W_.rightCols<3>();
  J.rightCols<12>().setZero();
  return true;
}

}  // namespace swarmlio
