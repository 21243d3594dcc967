#include "swarmlio/live/imu_rate_odometry.h"

#include "swarmlio/lio/imu_propagator.h"

namespace swarmlio::live {
namespace {

lio::ImuInput ToInput(const Eigen::Vector3d& w, const Eigen::Vector3d& a, double acceleration_to_m_s2) {
  lio::ImuInput u;
  u.angular_velocity_rad_s = w;
  u.specific_force_m_s2 = acceleration_to_m_s2 * a;
  return u;
}

}  // namespace

ImuRateOdometry::ImuRateOdometry(int64_t imu_time_offset_ns, size_t max_buffered_samples)
    : imu_time_offset_ns_(imu_time_offset_ns),
      max_buffered_samples_(max_buffered_samples == 0 ? 1 : max_buffered_samples) {}

void ImuRateOdometry::ResetToScan(const EgoState& state, int64_t stamp_ns,
                                  double acceleration_to_m_s2) {
  state_ = state;
  stamp_ns_ = stamp_ns;
  has_state_ = true;
  has_previous_ = false;
  for (const Sample& s : buffer_) {
    if (s.stamp_ns <= stamp_ns) {
      previous_ = s;  // the last sample at or before the scan end
      has_previous_ = true;
      continue;
    }
    StepTo(s, acceleration_to_m_s2);
  }
}

void ImuRateOdometry::StepTo(const Sample& next, double acceleration_to_m_s2) {
  const lio::ImuInput u_next =
      ToInput(next.angular_velocity_rad_s, next.linear_acceleration, acceleration_to_m_s2);
  lio::ImuInput u = u_next;
  if (has_previous_ && previous_.stamp_ns < next.stamp_ns) {
    const lio::ImuInput u_previous = ToInput(previous_.angular_velocity_rad_s,
                                        previous_.linear_acceleration, acceleration_to_m_s2);
    u = lio::MidpointInput(u_previous, previous_.stamp_ns, u_next, next.stamp_ns, stamp_ns_,
                      next.stamp_ns);
  }
  const double dt_s = static_cast<double>(next.stamp_ns - stamp_ns_) * 1e-9;
  if (dt_s > 0.0) state_ = lio::PropagateEgo(state_, u, dt_s);
  stamp_ns_ = next.stamp_ns;
  previous_ = next;
  has_previous_ = true;
}

bool ImuRateOdometry::AddImu(const ImuSample& sample, double acceleration_to_m_s2,
                             ImuRatePose* pose) {
  if (!sample.angular_velocity_rad_s.allFinite() || !sample.linear_acceleration.allFinite()) {
    return false;
  }
  Sample s;
  s.stamp_ns = sample.stamp_ns - imu_time_offset_ns_;
  s.angular_velocity_rad_s = sample.angular_velocity_rad_s;
  s.linear_acceleration = sample.linear_acceleration;
  if (!buffer_.empty() && s.stamp_ns <= buffer_.back().stamp_ns) return false;  // out of order
  buffer_.push_back(s);
  while (buffer_.size() > max_buffered_samples_) buffer_.pop_front();
  if (!has_state_ || s.stamp_ns <= stamp_ns_) return false;
  StepTo(s, acceleration_to_m_s2);
  *pose = Pose();
  return true;
}

ImuRatePose ImuRateOdometry::Pose() const {
  ImuRatePose p;
  p.stamp_ns = stamp_ns_;
  p.q_G_b = state_.q_G_b;
  p.p_b_in_G = state_.p_b_in_G;
  p.v_b_in_G = state_.v_b_in_G;
  p.angular_velocity_in_b_rad_s = previous_.angular_velocity_rad_s - state_.gyro_bias;
  return p;
}

}  // namespace swarmlio::live
