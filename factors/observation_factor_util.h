// Shared by the two mutual-observation factors (active_observation_factor.h,
// passive_observation_factor.h): a 3-residual cost over the ego block and one
// teammate block, whitened with a fixed innovation covariance S.
//
//   ObservationSqrtInformation(S) = L^-1 with S = L L^T (lower Cholesky), so
//     that |L^-1 e|^2 = e^T S^-1 e; CHECKs that S is positive definite (the
//     caller, swarm::DroneEstimator, regularizes every covariance it is
//     handed, so a failure here is a programming error).
//   Evaluate is the Ceres Evaluate of both factors.
//   WriteObservationJacobians lifts the tangent Jacobians (3x18 ego, 3x6
//     extrinsic, ErrorStateLayout order) to Ceres's ambient blocks: the
//     rotation columns through SO3Manifold::LiftTangentJacobian, the
//     Euclidean columns copied.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "factors/so3_manifold.h"
#include "swarmlio/common/check.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::observation_factor {

using EgoTangentJacobian = Eigen::Matrix<double, 3, EgoState::kTangentSize>;
using ExtrinsicTangentJacobian = Eigen::Matrix<double, 3, GlobalExtrinsic::kTangentSize>;

inline Eigen::Matrix3d SqrtInformation(const Eigen::Matrix3d& S, const char* what) {
  const Eigen::LLT<Eigen::Matrix3d> llt(S);
  CHECK(S.allFinite() && llt.info() == Eigen::Success)
      << what << " covariance is not positive definite:\n"
      << S;
  return llt.matrixL().solve(Eigen::Matrix3d::Identity()).triangularView<Eigen::Lower>();
}

inline void WriteObservationJacobians(const EgoTangentJacobian& J_ego,
                                      const ExtrinsicTangentJacobian& J_ext,
                                      double const* const* parameters, double** jacobians) {
  using EgoAmbient = Eigen::Matrix<double, 3, EgoState::kAmbientSize, Eigen::RowMajor>;
  using ExtrinsicAmbient = Eigen::Matrix<double, 3, GlobalExtrinsic::kAmbientSize, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {
    Eigen::Map<EgoAmbient> J(jacobians[0]);
    J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<3>(J_ego.leftCols<3>(), parameters[0]);
    J.rightCols<15>() = J_ego.rightCols<15>();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<ExtrinsicAmbient> J(jacobians[1]);
    J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<3>(J_ext.leftCols<3>(), parameters[1]);
    J.rightCols<3>() = J_ext.rightCols<3>();
  }
}

/// The Ceres Evaluate of either factor: residual from its Residual(), and
/// both tangent Jacobians (a few flops) from its TangentJacobian(), lifted
/// into the requested ambient blocks.
template <class Factor>
bool Evaluate(const Factor& factor, double const* const* parameters, double* residuals,
              double** jacobians) {
  const EgoState ego = EgoState::FromParameters(parameters[0]);
  const GlobalExtrinsic extrinsic = GlobalExtrinsic::FromParameters(parameters[1]);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = factor.Residual(ego, extrinsic);
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) return true;
  EgoTangentJacobian J_ego;
  ExtrinsicTangentJacobian J_ext;
  factor.TangentJacobian(ego, extrinsic, &J_ego, &J_ext);
  WriteObservationJacobians(J_ego, J_ext, parameters, jacobians);
  return true;
}

}  // namespace swarmlio::observation_factor
