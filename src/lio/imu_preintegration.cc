#include "swarmlio/lio/imu_preintegration.h"

#include <cmath>
#include <sstream>
#include <utility>

#include "swarmlio/common/check.h"

namespace swarmlio::lio {
namespace {

using L = ErrorStateLayout;
constexpr int kDim = 15;  // [dtheta dp dv dbg dba]: the ego segments before gravity
static_assert(L::kGravity.offset == kDim, "gravity must be the last ego segment");

}  // namespace

std::string ImuPreintegrationOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  const std::pair<const char*, double> variances[] = {
      {"gyro_cov_rad2_s2", process_noise.gyro_cov_rad2_s2},
      {"accel_cov_m2_s4", process_noise.accel_cov_m2_s4},
      {"gyro_bias_cov_rad2_s4", process_noise.gyro_bias_cov_rad2_s4},
      {"accel_bias_cov_m2_s6", process_noise.accel_bias_cov_m2_s6}};
  for (const auto& [key, value] : variances) {
    if (!(value > 0.0)) {
      return std::string("process_noise.") + key +
             ": must be > 0 for the preintegrated covariance to be positive definite";
    }
  }
  return "";
}

Status ImuPreintegration::Create(const ImuPreintegrationOptions& options,
                                 std::unique_ptr<ImuPreintegration>* preintegration) {
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument("imu preintegration options: " + error);
  preintegration->reset(new ImuPreintegration(options));
  return Status::Ok();
}

Status ImuPreintegration::Reset(int64_t start_stamp_ns,
                                const ImuSample& last_sample,
                                double acceleration_to_m_s2,
                                const Eigen::Vector3d& gyro_bias,
                                const Eigen::Vector3d& accel_bias) {
  const ImuInput u = ToImuInput(last_sample, acceleration_to_m_s2);
  if (!u.angular_velocity_rad_s.allFinite() || !u.specific_force_m_s2.allFinite() ||
      !std::isfinite(acceleration_to_m_s2) || !gyro_bias.allFinite() || !accel_bias.allFinite()) {
    return Status::InvalidArgument(
        "imu preintegration: non-finite initial sample, unit factor or biases");
  }
  if (last_sample.stamp_ns > start_stamp_ns) {
    std::ostringstream os;
    os << "imu preintegration: the last sample (stamp " << last_sample.stamp_ns
       << " ns) must not be after the start " << start_stamp_ns << " ns";
    return Status::InvalidArgument(os.str());
  }
  stepper_.Reset(start_stamp_ns, last_sample, acceleration_to_m_s2);
  initialized_ = true;
  Restart(gyro_bias, accel_bias);
  return Status::Ok();
}

double ImuPreintegration::SumOfSquaredSteps() const {
  double sum = 0.0;
  for (const Step& step : steps_) sum += step.dt_s * step.dt_s;
  return sum;
}

void ImuPreintegration::Restart(const Eigen::Vector3d& gyro_bias,
                                const Eigen::Vector3d& accel_bias) {
  CHECK(initialized_) << "ImuPreintegration::Restart before Reset";
  start_stamp_ns_ = stepper_.stamp_ns();
  steps_.clear();
  ClearIntegral(gyro_bias, accel_bias);
  Publish();
}

void ImuPreintegration::Reintegrate(const Eigen::Vector3d& gyro_bias,
                                    const Eigen::Vector3d& accel_bias) {
  CHECK(initialized_) << "ImuPreintegration::Reintegrate before Reset";
  ClearIntegral(gyro_bias, accel_bias);
  for (const Step& step : steps_) Integrate(step);
  Publish();
}

void ImuPreintegration::ClearIntegral(const Eigen::Vector3d& gyro_bias,
                                      const Eigen::Vector3d& accel_bias) {
  delta_ = EgoState();
  delta_.gyro_bias = gyro_bias;
  delta_.accel_bias = accel_bias;
  delta_.g_in_G.setZero();
  transition_.setIdentity();
  covariance_.setZero();
}

void ImuPreintegration::Integrate(const Step& step) {
  EgoMatrix F;
  EgoNoiseMatrix G;
  EgoProcessJacobians(delta_, step.input, step.dt_s, &F, &G);
  delta_ = PropagateEgo(delta_, step.input, step.dt_s);
  // Gravity is not a preintegration error (delta_.g = 0 exactly): drop its
  // rows and columns.
  const Matrix15 F15 = F.topLeftCorner<kDim, kDim>();
  const Eigen::Matrix<double, kDim, ImuNoiseLayout::kDim> G15 = G.topRows<kDim>();
  transition_ = F15 * transition_;
  const Matrix15 P = F15 * covariance_ * F15.transpose() + G15 * Q_ * G15.transpose();
  covariance_ = 0.5 * (P + P.transpose());
}

void ImuPreintegration::Advance(const ImuStep& step) {
  const Step recorded{step.input, step.dt_s};
  Integrate(recorded);
  steps_.push_back(recorded);
  stepper_.Advance(step);
  Publish();
}

void ImuPreintegration::Publish() {
  PreintegratedImu& m = preintegrated_;
  m.dt_s = ToSeconds(stepper_.stamp_ns() - start_stamp_ns_);
  m.delta_R = delta_.R_G_b();
  m.delta_v = delta_.v_b_in_G;
  m.delta_p = delta_.p_b_in_G;
  m.gyro_bias_lin = delta_.gyro_bias;
  m.accel_bias_lin = delta_.accel_bias;
  const auto jacobian = [this](const Segment& row, const Segment& col) {
    return Eigen::Matrix3d(transition_.block<3, 3>(row.offset, col.offset));
  };
  m.dR_dbg = jacobian(L::kRotation, L::kGyroBias);
  m.dv_dbg = jacobian(L::kVelocity, L::kGyroBias);
  m.dv_dba = jacobian(L::kVelocity, L::kAccelBias);
  m.dp_dbg = jacobian(L::kPosition, L::kGyroBias);
  m.dp_dba = jacobian(L::kPosition, L::kAccelBias);
  m.covariance.setZero();
  m.covariance.topLeftCorner<kDim, kDim>() = covariance_;
  const double floor = options_.gravity_stddev_floor_m_s2;
  m.covariance.block<3, 3>(L::kGravity.offset, L::kGravity.offset) =
      floor * floor * Eigen::Matrix3d::Identity();
}

Status ImuPreintegration::AddImu(const ImuSample& sample) {
  CHECK(initialized_) << "ImuPreintegration::AddImu before Reset";
  ImuSampleStepper::Action action;
  ImuStep step;
  const Status status = stepper_.Accept(sample, &action, &step);
  if (!status.ok() || action == ImuSampleStepper::Action::kSkip) return status;
  if (action == ImuSampleStepper::Action::kStep) Advance(step);
  stepper_.Hold(sample);
  return Status::Ok();
}

Status ImuPreintegration::IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample) {
  CHECK(initialized_) << "ImuPreintegration::IntegrateTo before Reset";
  ImuStep step;
  bool needed = false;
  const Status status = stepper_.StepTo(stamp_ns, next_sample, &step, &needed);
  if (status.ok() && needed) Advance(step);
  return status;
}

}  // namespace swarmlio::lio
