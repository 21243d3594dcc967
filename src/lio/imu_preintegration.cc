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

bool IsFinite(const ImuInput& u) {
  return u.angular_velocity_rad_s.allFinite() && u.specific_force_m_s2.allFinite();
}

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
  if (!IsFinite(u) || !std::isfinite(acceleration_to_m_s2) || !gyro_bias.allFinite() ||
      !accel_bias.allFinite()) {
    return Status::InvalidArgument(
        "imu preintegration: non-finite initial sample, unit factor or biases");
  }
  if (last_sample.stamp_ns > start_stamp_ns) {
    std::ostringstream os;
    os << "imu preintegration: the last sample (stamp " << last_sample.stamp_ns
       << " ns) must not be after the start " << start_stamp_ns << " ns";
    return Status::InvalidArgument(os.str());
  }
  stamp_ns_ = start_stamp_ns;
  last_sample_stamp_ns_ = last_sample.stamp_ns;
  last_input_ = u;
  acceleration_to_m_s2_ = acceleration_to_m_s2;
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
  start_stamp_ns_ = stamp_ns_;
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

void ImuPreintegration::Advance(const ImuInput& u, int64_t stamp_ns) {
  const Step step{u, ToSeconds(stamp_ns - stamp_ns_)};
  Integrate(step);
  steps_.push_back(step);
  stamp_ns_ = stamp_ns;
  Publish();
}

void ImuPreintegration::Publish() {
  PreintegratedImu& m = preintegrated_;
  m.dt_s = ToSeconds(stamp_ns_ - start_stamp_ns_);
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

Status ImuPreintegration::CheckGap(int64_t stamp_ns) const {
  const double dt = ToSeconds(stamp_ns - stamp_ns_);
  if (dt <= options_.max_gap_s) return Status::Ok();
  std::ostringstream os;
  os << "imu preintegration: gap of " << dt << " s from " << stamp_ns_ << " ns to " << stamp_ns
     << " ns exceeds max_gap_s = " << options_.max_gap_s << " s; not integrated";
  return Status::OutOfRange(os.str());
}

Status ImuPreintegration::AddImu(const ImuSample& sample) {
  CHECK(initialized_) << "ImuPreintegration::AddImu before Reset";
  const ImuInput u = ToImuInput(sample, acceleration_to_m_s2_);
  if (!IsFinite(u)) {
    ++num_rejected_non_finite_;
    return Status::InvalidArgument("imu preintegration: non-finite IMU sample at stamp " +
                                   std::to_string(sample.stamp_ns) + " ns rejected");
  }
  if (sample.stamp_ns == last_sample_stamp_ns_) {
    ++num_skipped_duplicate_;
    return Status::Ok();
  }
  if (sample.stamp_ns == stamp_ns_ && sample.stamp_ns > last_sample_stamp_ns_) {
    // IntegrateTo() already reached this stamp: the sample only becomes the
    // input from here on.
    last_input_ = u;
    last_sample_stamp_ns_ = sample.stamp_ns;
    return Status::Ok();
  }
  if (sample.stamp_ns <= stamp_ns_) {
    ++num_skipped_out_of_order_;
    return Status::Ok();
  }
  const Status gap = CheckGap(sample.stamp_ns);
  if (!gap.ok()) {
    ++num_gaps_;
    return gap;
  }
  Advance(MidpointInput(u, sample.stamp_ns, sample.stamp_ns), sample.stamp_ns);
  last_input_ = u;
  last_sample_stamp_ns_ = sample.stamp_ns;
  return Status::Ok();
}

Status ImuPreintegration::IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample) {
  CHECK(initialized_) << "ImuPreintegration::IntegrateTo before Reset";
  if (stamp_ns == stamp_ns_) return Status::Ok();
  if (stamp_ns < stamp_ns_) {
    std::ostringstream os;
    os << "imu preintegration: cannot integrate back in time from " << stamp_ns_ << " ns to "
       << stamp_ns << " ns";
    return Status::OutOfRange(os.str());
  }
  ImuInput u = last_input_;  // zero-order hold
  if (next_sample != nullptr) {
    const ImuInput next = ToImuInput(*next_sample, acceleration_to_m_s2_);
    if (next_sample->stamp_ns < stamp_ns || !IsFinite(next)) {
      std::ostringstream os;
      os << "imu preintegration: next sample (stamp " << next_sample->stamp_ns
         << " ns) must be finite and not before the target " << stamp_ns << " ns";
      return Status::InvalidArgument(os.str());
    }
    u = MidpointInput(next, next_sample->stamp_ns, stamp_ns);
  }
  const Status gap = CheckGap(stamp_ns);
  if (!gap.ok()) {
    ++num_gaps_;
    return gap;
  }
  Advance(u, stamp_ns);
  return Status::Ok();
}

// The propagator's interpolation (the same function: same rounding).
ImuInput ImuPreintegration::MidpointInput(const ImuInput& next,
                                          int64_t next_stamp_ns,
                                          int64_t end_ns) const {
  return lio::MidpointInput(last_input_, last_sample_stamp_ns_, next, next_stamp_ns, stamp_ns_,
                                 end_ns);
}

}  // namespace swarmlio::lio
