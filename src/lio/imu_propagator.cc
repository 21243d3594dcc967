#include "swarmlio/lio/imu_propagator.h"

#include <sstream>

#include "swarmlio/common/check.h"
#include "swarmlio/lio/imu_initializer.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

using L = ErrorStateLayout;
using N = ImuNoiseLayout;

// 3x3 block (rows of segment r, columns of segment c).
template <class M>
auto Block(M& m, const Segment& r, const Segment& c) {
  return m.template block<3, 3>(r.offset, c.offset);
}

// The quantities of one interval that the state, the Jacobians and the
// recorded scan poses share (docs/imu.md, "Discrete model").
struct Interval {
  Eigen::Vector3d w;         // unbiased angular rate [rad/s]
  Eigen::Vector3d a;         // unbiased specific force [m/s^2]
  Eigen::Vector3d phi;       // w dt [rad]
  Eigen::Matrix3d R;         // R_G_b at the interval start
  Eigen::Matrix3d M;         // Exp(phi / 2)
  Eigen::Vector3d acc_in_G;  // R M a + g [m/s^2]
};

Interval MakeInterval(const EgoState& x,
                      const ImuInput& u,
                      double dt,
                      const ImuNoiseVector& noise) {
  Interval k;
  k.w = u.angular_velocity_rad_s - x.gyro_bias - noise.segment<3>(N::kGyro.offset);
  k.a = u.specific_force_m_s2 - x.accel_bias - noise.segment<3>(N::kAccel.offset);
  k.phi = k.w * dt;
  k.R = x.R_G_b();
  k.M = so3::Exp(0.5 * k.phi);
  k.acc_in_G = k.R * (k.M * k.a) + x.g_in_G;
  return k;
}

}  // namespace

EgoState PropagateEgo(const EgoState& x, const ImuInput& u, double dt_s, const ImuNoiseVector& w) {
  const Interval k = MakeInterval(x, u, dt_s, w);
  EgoState y = x;
  y.q_G_b = (x.q_G_b * so3::ExpQuaternion(k.phi)).normalized();
  y.p_b_in_G = x.p_b_in_G + x.v_b_in_G * dt_s + 0.5 * dt_s * dt_s * k.acc_in_G;
  y.v_b_in_G = x.v_b_in_G + k.acc_in_G * dt_s;
  y.gyro_bias = x.gyro_bias + w.segment<3>(N::kGyroBiasWalk.offset) * dt_s;
  y.accel_bias = x.accel_bias + w.segment<3>(N::kAccelBiasWalk.offset) * dt_s;
  y.g_in_G = x.g_in_G;
  return y;
}

void EgoProcessJacobians(
    const EgoState& x, const ImuInput& u, double dt_s, EgoMatrix* F_out, EgoNoiseMatrix* G_out) {
  const Interval k = MakeInterval(x, u, dt_s, ImuNoiseVector::Zero());
  const double dt = dt_s;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d RM = k.R * k.M;
  // Partial derivatives of a_G = R Exp(phi/2) a + g (right perturbations):
  const Eigen::Matrix3d dacc_dtheta = -k.R * so3::Hat(k.M * k.a);
  // d a_G / d phi = -1/2 R M [a]x Jr(phi/2), and d phi / d b_g = -dt I.
  const Eigen::Matrix3d dacc_dbg = 0.5 * dt * RM * so3::Hat(k.a) * so3::RightJacobian(0.5 * k.phi);
  const Eigen::Matrix3d dacc_dba = -RM;
  const Eigen::Matrix3d dtheta_dbg = -so3::RightJacobian(k.phi) * dt;
  const double half_dt2 = 0.5 * dt * dt;

  EgoMatrix& F = *F_out;
  F.setIdentity();
  Block(F, L::kRotation, L::kRotation) = so3::Exp(-k.phi);
  Block(F, L::kRotation, L::kGyroBias) = dtheta_dbg;
  Block(F, L::kPosition, L::kRotation) = half_dt2 * dacc_dtheta;
  Block(F, L::kPosition, L::kVelocity) = dt * I;
  Block(F, L::kPosition, L::kGyroBias) = half_dt2 * dacc_dbg;
  Block(F, L::kPosition, L::kAccelBias) = half_dt2 * dacc_dba;
  Block(F, L::kPosition, L::kGravity) = half_dt2 * I;
  Block(F, L::kVelocity, L::kRotation) = dt * dacc_dtheta;
  Block(F, L::kVelocity, L::kGyroBias) = dt * dacc_dbg;
  Block(F, L::kVelocity, L::kAccelBias) = dt * dacc_dba;
  Block(F, L::kVelocity, L::kGravity) = dt * I;

  // n_g and n_a enter exactly like b_g and b_a.
  EgoNoiseMatrix& G = *G_out;
  G.setZero();
  Block(G, L::kRotation, N::kGyro) = dtheta_dbg;
  Block(G, L::kPosition, N::kGyro) = half_dt2 * dacc_dbg;
  Block(G, L::kPosition, N::kAccel) = half_dt2 * dacc_dba;
  Block(G, L::kVelocity, N::kGyro) = dt * dacc_dbg;
  Block(G, L::kVelocity, N::kAccel) = dt * dacc_dba;
  Block(G, L::kGyroBias, N::kGyroBiasWalk) = dt * I;
  Block(G, L::kAccelBias, N::kAccelBiasWalk) = dt * I;
}

Eigen::Matrix<double, ImuNoiseLayout::kDim, ImuNoiseLayout::kDim> EgoNoiseCovariance(
    const ProcessNoiseOptions& noise) {
  Eigen::Matrix<double, N::kDim, N::kDim> Q = Eigen::Matrix<double, N::kDim, N::kDim>::Zero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Block(Q, N::kGyro, N::kGyro) = noise.gyro_cov_rad2_s2 * I;
  Block(Q, N::kAccel, N::kAccel) = noise.accel_cov_m2_s4 * I;
  Block(Q, N::kGyroBiasWalk, N::kGyroBiasWalk) = noise.gyro_bias_cov_rad2_s4 * I;
  Block(Q, N::kAccelBiasWalk, N::kAccelBiasWalk) = noise.accel_bias_cov_m2_s6 * I;
  return Q;
}

Status ImuPropagator::Create(const ImuPropagatorOptions& options,
                             std::unique_ptr<ImuPropagator>* propagator) {
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument("imu propagator options: " + error);
  propagator->reset(new ImuPropagator(options));
  return Status::Ok();
}

Status ImuPropagator::Reset(const SwarmState& state,
                            const Eigen::MatrixXd& P,
                            const ImuSample& sample,
                            double acceleration_to_m_s2) {
  if (P.rows() != state.Dim() || P.cols() != state.Dim()) {
    std::ostringstream os;
    os << "imu propagator: covariance is " << P.rows() << "x" << P.cols() << ", state dim is "
       << state.Dim();
    return Status::InvalidArgument(os.str());
  }
  const ImuInput u = ToImuInput(sample, acceleration_to_m_s2);
  if (!u.angular_velocity_rad_s.allFinite() || !u.specific_force_m_s2.allFinite() ||
      !P.allFinite()) {
    return Status::InvalidArgument("imu propagator: non-finite initial sample or covariance");
  }
  state_ = state;
  P_ = P;
  stepper_.Reset(sample.stamp_ns, sample, acceleration_to_m_s2);
  initialized_ = true;
  StartScan();
  return Status::Ok();
}

Status ImuPropagator::Reset(const ImuInitialization& init) {
  SwarmState state;
  state.ego = init.state;
  return Reset(state, Eigen::MatrixXd(init.covariance), init.last_sample,
               init.acceleration_to_m_s2);
}

Status ImuPropagator::AddImu(const ImuSample& sample) {
  CHECK(initialized_) << "ImuPropagator::AddImu before Reset";
  ImuSampleStepper::Action action;
  ImuStep step;
  const Status status = stepper_.Accept(sample, &action, &step);
  if (!status.ok() || action == ImuSampleStepper::Action::kSkip) return status;
  if (action == ImuSampleStepper::Action::kStep) Step(step);
  stepper_.Hold(sample);
  // The newest pose's held input is the sample itself until the next step.
  scan_poses_.back() = CurrentPose(stepper_.last_input());
  return Status::Ok();
}

Status ImuPropagator::PropagateTo(int64_t stamp_ns, const ImuSample* next_sample) {
  CHECK(initialized_) << "ImuPropagator::PropagateTo before Reset";
  ImuStep step;
  bool needed = false;
  const Status status = stepper_.StepTo(stamp_ns, next_sample, &step, &needed);
  if (status.ok() && needed) Step(step);
  return status;
}

void ImuPropagator::StartScan() {
  scan_poses_.clear();
  scan_poses_.push_back(CurrentPose(stepper_.last_input()));
}

void ImuPropagator::SetState(const SwarmState& state, const Eigen::MatrixXd& P) {
  CHECK_EQ(P.rows(), state.Dim());
  CHECK_EQ(P.cols(), state.Dim());
  state_ = state;
  P_ = P;
  StartScan();
}

ImuPose ImuPropagator::CurrentPose(const ImuInput& u) const {
  const EgoState& x = state_.ego;
  ImuPose pose;
  pose.stamp_ns = stepper_.stamp_ns();
  pose.R_G_b = x.R_G_b();
  pose.p_b_in_G = x.p_b_in_G;
  pose.v_b_in_G = x.v_b_in_G;
  pose.angular_velocity_in_b_rad_s = u.angular_velocity_rad_s - x.gyro_bias;
  pose.acc_in_G_m_s2 = pose.R_G_b * (u.specific_force_m_s2 - x.accel_bias) + x.g_in_G;
  return pose;
}

void ImuPropagator::Step(const ImuStep& step) {
  EgoMatrix F;
  EgoNoiseMatrix G;
  EgoProcessJacobians(state_.ego, step.input, step.dt_s, &F, &G);
  // The pose that starts this interval holds exactly the input integrated.
  const Interval k = MakeInterval(state_.ego, step.input, step.dt_s, ImuNoiseVector::Zero());
  scan_poses_.back().angular_velocity_in_b_rad_s = k.w;
  scan_poses_.back().acc_in_G_m_s2 = k.acc_in_G;

  state_.ego = PropagateEgo(state_.ego, step.input, step.dt_s);
  PropagateCovariance(F, G, step.dt_s);
  stepper_.Advance(step);
  scan_poses_.push_back(CurrentPose(step.input));
}

void ImuPropagator::PropagateCovariance(const EgoMatrix& F, const EgoNoiseMatrix& G, double dt_s) {
  constexpr int kEgo = L::kEgoDim;
  // F = diag(F_ego, I): only the ego rows and columns change.
  const Eigen::MatrixXd top = F * P_.topRows(kEgo);
  P_.topRows(kEgo) = top;
  const Eigen::MatrixXd left = P_.leftCols(kEgo) * F.transpose();
  P_.leftCols(kEgo) = left;
  const auto Q = EgoNoiseCovariance(options_.process_noise);
  P_.topLeftCorner(kEgo, kEgo) += G * Q * G.transpose();
  // Teammate random walks: R Exp(n_R dt), p + n_p dt.
  const double dt2 = dt_s * dt_s;
  for (int id : state_.layout().teammate_ids()) {
    const Segment rot = state_.layout().TeammateRotation(id);
    const Segment trans = state_.layout().TeammateTranslation(id);
    P_.block<3, 3>(rot.offset, rot.offset).diagonal().array() +=
        dt2 * options_.process_noise.teammate_rotation_cov_rad2_s2;
    P_.block<3, 3>(trans.offset, trans.offset).diagonal().array() +=
        dt2 * options_.process_noise.teammate_translation_cov_m2_s2;
  }
  // Only the ego rows and columns changed: symmetrize those (O(18 n), not O(n^2)).
  const Eigen::MatrixXd ego_rows = 0.5 * (P_.topRows(kEgo) + P_.leftCols(kEgo).transpose());
  P_.topRows(kEgo) = ego_rows;
  P_.leftCols(kEgo) = ego_rows.transpose();
}

}  // namespace swarmlio::lio
