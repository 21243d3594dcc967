#include "factors/imu_preintegration_factor.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <sstream>

#include "factors/so3_manifold.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

using L = ErrorStateLayout;
using Matrix18 = PreintegratedImu::Matrix18;

// 3x3 block (rows of segment r, columns of segment c).
auto Block(Matrix18& m, const Segment& r, const Segment& c) {
  return m.block<3, 3>(r.offset, c.offset);
}

bool AllFinite(const PreintegratedImu& m) {
  return std::isfinite(m.dt_s) && m.delta_R.allFinite() && m.delta_v.allFinite() &&
         m.delta_p.allFinite() && m.gyro_bias_lin.allFinite() && m.accel_bias_lin.allFinite() &&
         m.dR_dbg.allFinite() && m.dv_dbg.allFinite() && m.dv_dba.allFinite() &&
         m.dp_dbg.allFinite() && m.dp_dba.allFinite() && m.covariance.allFinite();
}

// Writes the ambient (18 x 19, row-major) Jacobian of one ego block.
void WriteAmbientJacobian(const Matrix18& J_t, const double* x, double* jacobian) {
  using Ambient =
      Eigen::Matrix<double, EgoState::kTangentSize, EgoState::kAmbientSize, Eigen::RowMajor>;
  Eigen::Map<Ambient> J(jacobian);
  J.leftCols<4>() = SO3Manifold::LiftTangentJacobian<EgoState::kTangentSize>(J_t.leftCols<3>(), x);
  J.rightCols<15>() = J_t.rightCols<15>();
}

}  // namespace

Eigen::Matrix3d PreintegratedImu::CorrectedDeltaR(const Eigen::Vector3d& gyro_bias) const {
  return delta_R * so3::Exp(dR_dbg * (gyro_bias - gyro_bias_lin));
}

Eigen::Vector3d PreintegratedImu::CorrectedDeltaV(const Eigen::Vector3d& gyro_bias,
                                                  const Eigen::Vector3d& accel_bias) const {
  return delta_v + dv_dbg * (gyro_bias - gyro_bias_lin) + dv_dba * (accel_bias - accel_bias_lin);
}

Eigen::Vector3d PreintegratedImu::CorrectedDeltaP(const Eigen::Vector3d& gyro_bias,
                                                  const Eigen::Vector3d& accel_bias) const {
  return delta_p + dp_dbg * (gyro_bias - gyro_bias_lin) + dp_dba * (accel_bias - accel_bias_lin);
}

Status ImuPreintegrationFactor::Create(const PreintegratedImu& preintegrated,
                                       std::unique_ptr<ImuPreintegrationFactor>* factor) {
  if (!AllFinite(preintegrated)) {
    return Status::InvalidArgument("imu preintegration factor: non-finite preintegrated values");
  }
  if (!(preintegrated.dt_s > 0.0)) {
    std::ostringstream os;
    os << "imu preintegration factor: interval dt_s = " << preintegrated.dt_s
       << " s must be positive";
    return Status::InvalidArgument(os.str());
  }
  PreintegratedImu m = preintegrated;
  m.covariance = 0.5 * (preintegrated.covariance + preintegrated.covariance.transpose());
  const Eigen::LLT<Matrix18> llt(m.covariance);
  const Matrix18 U = llt.matrixL();
  if (llt.info() != Eigen::Success || (U.diagonal().array() <= 0.0).any()) {
    std::ostringstream os;
    os << "imu preintegration factor: covariance over " << m.dt_s
       << " s is not positive definite (zero noise variances, or a single IMU interval?)";
    return Status::InvalidArgument(os.str());
  }
  const Matrix18 sqrt_information =
      U.triangularView<Eigen::Lower>().solve(Matrix18::Identity()).triangularView<Eigen::Lower>();
  factor->reset(new ImuPreintegrationFactor(m, sqrt_information));
  return Status::Ok();
}

ImuPreintegrationFactor::ResidualVector ImuPreintegrationFactor::Compute(
    const EgoState& ego_k,
    const EgoState& ego_k1,
    TangentJacobianMatrix* E_k,
    TangentJacobianMatrix* E_k1) const {
  const PreintegratedImu& m = preintegrated_;
  const double T = m.dt_s;
  const Eigen::Matrix3d R_k = so3::RotationOf(ego_k.q_G_b);
  const Eigen::Matrix3d R_k1 = so3::RotationOf(ego_k1.q_G_b);
  const Eigen::Matrix3d Rt_k = R_k.transpose();
  const Eigen::Vector3d dbg = ego_k.gyro_bias - m.gyro_bias_lin;
  const Eigen::Vector3d c = m.dR_dbg * dbg;
  const Eigen::Matrix3d delta_R_c = m.delta_R * so3::Exp(c);
  const Eigen::Matrix3d E = delta_R_c.transpose() * Rt_k * R_k1;
  const Eigen::Vector3d d_p =
      ego_k1.p_b_in_G - ego_k.p_b_in_G - ego_k.v_b_in_G * T - 0.5 * T * T * ego_k.g_in_G;
  const Eigen::Vector3d d_v = ego_k1.v_b_in_G - ego_k.v_b_in_G - T * ego_k.g_in_G;
  const Eigen::Vector3d d_p_in_bk = Rt_k * d_p;
  const Eigen::Vector3d d_v_in_bk = Rt_k * d_v;

  ResidualVector e;
  e.segment<3>(L::kRotation.offset) = so3::Log(E);
  e.segment<3>(L::kPosition.offset) =
      d_p_in_bk - m.CorrectedDeltaP(ego_k.gyro_bias, ego_k.accel_bias);
  e.segment<3>(L::kVelocity.offset) =
      d_v_in_bk - m.CorrectedDeltaV(ego_k.gyro_bias, ego_k.accel_bias);
  e.segment<3>(L::kGyroBias.offset) = ego_k1.gyro_bias - ego_k.gyro_bias;
  e.segment<3>(L::kAccelBias.offset) = ego_k1.accel_bias - ego_k.accel_bias;
  e.segment<3>(L::kGravity.offset) = ego_k1.g_in_G - ego_k.g_in_G;
  if (E_k == nullptr && E_k1 == nullptr) return e;

  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Jr_inv = so3::RightJacobianInverse(e.segment<3>(L::kRotation.offset));
  if (E_k != nullptr) {
    Matrix18& J = *E_k;
    J.setZero();
    Block(J, L::kRotation, L::kRotation) = -Jr_inv * R_k1.transpose() * R_k;
    Block(J, L::kRotation, L::kGyroBias) =
        -Jr_inv * E.transpose() * so3::RightJacobian(c) * m.dR_dbg;
    Block(J, L::kPosition, L::kRotation) = so3::Hat(d_p_in_bk);
    Block(J, L::kPosition, L::kPosition) = -Rt_k;
    Block(J, L::kPosition, L::kVelocity) = -T * Rt_k;
    Block(J, L::kPosition, L::kGyroBias) = -m.dp_dbg;
    Block(J, L::kPosition, L::kAccelBias) = -m.dp_dba;
    Block(J, L::kPosition, L::kGravity) = -0.5 * T * T * Rt_k;
    Block(J, L::kVelocity, L::kRotation) = so3::Hat(d_v_in_bk);
    Block(J, L::kVelocity, L::kVelocity) = -Rt_k;
    Block(J, L::kVelocity, L::kGyroBias) = -m.dv_dbg;
    Block(J, L::kVelocity, L::kAccelBias) = -m.dv_dba;
    Block(J, L::kVelocity, L::kGravity) = -T * Rt_k;
    Block(J, L::kGyroBias, L::kGyroBias) = -I;
    Block(J, L::kAccelBias, L::kAccelBias) = -I;
    Block(J, L::kGravity, L::kGravity) = -I;
  }
  if (E_k1 != nullptr) {
    Matrix18& J = *E_k1;
    J.setZero();
    Block(J, L::kRotation, L::kRotation) = Jr_inv;
    Block(J, L::kPosition, L::kPosition) = Rt_k;
    Block(J, L::kVelocity, L::kVelocity) = Rt_k;
    Block(J, L::kGyroBias, L::kGyroBias) = I;
    Block(J, L::kAccelBias, L::kAccelBias) = I;
    Block(J, L::kGravity, L::kGravity) = I;
  }
  return e;
}

ImuPreintegrationFactor::ResidualVector ImuPreintegrationFactor::Error(
    const EgoState& ego_k, const EgoState& ego_k1) const {
  return Compute(ego_k, ego_k1, nullptr, nullptr);
}

ImuPreintegrationFactor::ResidualVector ImuPreintegrationFactor::Residual(
    const EgoState& ego_k, const EgoState& ego_k1) const {
  return sqrt_information_.triangularView<Eigen::Lower>() * Error(ego_k, ego_k1);
}

void ImuPreintegrationFactor::TangentJacobian(const EgoState& ego_k,
                                              const EgoState& ego_k1,
                                              TangentJacobianMatrix* J_k,
                                              TangentJacobianMatrix* J_k1) const {
  Compute(ego_k, ego_k1, J_k, J_k1);
  if (J_k != nullptr) *J_k = sqrt_information_.triangularView<Eigen::Lower>() * *J_k;
  if (J_k1 != nullptr) *J_k1 = sqrt_information_.triangularView<Eigen::Lower>() * *J_k1;
}

bool ImuPreintegrationFactor::Evaluate(double const* const* parameters,
                                       double* residuals,
                                       double** jacobians) const {
  const EgoState ego_k = EgoState::FromParameters(parameters[0]);
  const EgoState ego_k1 = EgoState::FromParameters(parameters[1]);
  const bool want_k = jacobians != nullptr && jacobians[0] != nullptr;
  const bool want_k1 = jacobians != nullptr && jacobians[1] != nullptr;
  Matrix18 J_k, J_k1;
  const ResidualVector e =
      Compute(ego_k, ego_k1, want_k ? &J_k : nullptr, want_k1 ? &J_k1 : nullptr);
  const auto W = sqrt_information_.triangularView<Eigen::Lower>();
  Eigen::Map<ResidualVector> r(residuals);
  r = W * e;
  if (want_k) WriteAmbientJacobian(W * J_k, parameters[0], jacobians[0]);
  if (want_k1) WriteAmbientJacobian(W * J_k1, parameters[1], jacobians[1]);
  return true;
}

}  // namespace swarmlio
