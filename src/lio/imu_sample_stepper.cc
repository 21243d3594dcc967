#include "swarmlio/lio/imu_sample_stepper.h"

#include <sstream>
#include <utility>

#include "swarmlio/common/time.h"

namespace swarmlio::lio {
namespace {

bool IsFinite(const ImuInput& u) {
  return u.angular_velocity_rad_s.allFinite() && u.specific_force_m_s2.allFinite();
}

}  // namespace

ImuInput ToImuInput(const ImuSample& sample, double acceleration_to_m_s2) {
  ImuInput u;
  u.angular_velocity_rad_s = sample.angular_velocity_rad_s;
  u.specific_force_m_s2 = acceleration_to_m_s2 * sample.linear_acceleration;
  return u;
}

ImuInput MidpointInput(const ImuInput& last,
                       int64_t last_stamp_ns,
                       const ImuInput& next,
                       int64_t next_stamp_ns,
                       int64_t from_ns,
                       int64_t to_ns) {
  const double span_s = ToSeconds(next_stamp_ns - last_stamp_ns);
  const double t_mid_s =
      0.5 * (ToSeconds(from_ns - last_stamp_ns) + ToSeconds(to_ns - last_stamp_ns));
  const double alpha = span_s > 0.0 ? t_mid_s / span_s : 0.0;
  ImuInput mid;
  mid.angular_velocity_rad_s = last.angular_velocity_rad_s +
                               alpha * (next.angular_velocity_rad_s - last.angular_velocity_rad_s);
  mid.specific_force_m_s2 =
      last.specific_force_m_s2 + alpha * (next.specific_force_m_s2 - last.specific_force_m_s2);
  return mid;
}

ImuSampleStepper::ImuSampleStepper(std::string owner, double max_gap_s, std::string gap_note)
    : owner_(std::move(owner)), max_gap_s_(max_gap_s), gap_note_(std::move(gap_note)) {}

void ImuSampleStepper::Reset(int64_t stamp_ns,
                             const ImuSample& last_sample,
                             double acceleration_to_m_s2) {
  stamp_ns_ = stamp_ns;
  last_sample_ = last_sample;
  last_input_ = ToImuInput(last_sample, acceleration_to_m_s2);
  acceleration_to_m_s2_ = acceleration_to_m_s2;
}

Status ImuSampleStepper::Accept(const ImuSample& sample, Action* action, ImuStep* step) {
  *action = Action::kSkip;
  const ImuInput u = ToImuInput(sample, acceleration_to_m_s2_);
  if (!IsFinite(u)) {
    ++num_rejected_non_finite_;
    return Status::InvalidArgument(owner_ + ": non-finite IMU sample at stamp " +
                                   std::to_string(sample.stamp_ns) + " ns rejected");
  }
  if (sample.stamp_ns == last_sample_.stamp_ns) {
    ++num_skipped_duplicate_;
    return Status::Ok();
  }
  if (sample.stamp_ns == stamp_ns_ && sample.stamp_ns > last_sample_.stamp_ns) {
    // StepTo() already reached this stamp: the sample only becomes the input
    // from here on.
    *action = Action::kInputOnly;
    return Status::Ok();
  }
  if (sample.stamp_ns <= stamp_ns_) {
    ++num_skipped_out_of_order_;
    return Status::Ok();
  }
  const Status gap = CheckGap(sample.stamp_ns);
  if (!gap.ok()) return gap;
  // Input at the midpoint time of [stamp_ns_, sample], linearly interpolated
  // between the previous sample and this one (the plain mean of the two when
  // the integration stands on the previous sample).
  step->input = Midpoint(u, sample.stamp_ns, sample.stamp_ns);
  step->dt_s = ToSeconds(sample.stamp_ns - stamp_ns_);
  step->end_ns = sample.stamp_ns;
  *action = Action::kStep;
  return Status::Ok();
}

Status ImuSampleStepper::StepTo(int64_t stamp_ns,
                                const ImuSample* next_sample,
                                ImuStep* step,
                                bool* needed) {
  *needed = false;
  if (stamp_ns == stamp_ns_) return Status::Ok();
  if (stamp_ns < stamp_ns_) {
    std::ostringstream os;
    os << owner_ << ": cannot step back in time from " << stamp_ns_ << " ns to " << stamp_ns
       << " ns";
    return Status::OutOfRange(os.str());
  }
  ImuInput u = last_input_;  // zero-order hold
  if (next_sample != nullptr) {
    const ImuInput next = ToImuInput(*next_sample, acceleration_to_m_s2_);
    if (next_sample->stamp_ns < stamp_ns || !IsFinite(next)) {
      std::ostringstream os;
      os << owner_ << ": next sample (stamp " << next_sample->stamp_ns
         << " ns) must be finite and not before the target " << stamp_ns << " ns";
      return Status::InvalidArgument(os.str());
    }
    u = Midpoint(next, next_sample->stamp_ns, stamp_ns);
  }
  const Status gap = CheckGap(stamp_ns);
  if (!gap.ok()) return gap;
  step->input = u;
  step->dt_s = ToSeconds(stamp_ns - stamp_ns_);
  step->end_ns = stamp_ns;
  *needed = true;
  return Status::Ok();
}

void ImuSampleStepper::Hold(const ImuSample& sample) {
  last_sample_ = sample;
  last_input_ = ToImuInput(sample, acceleration_to_m_s2_);
}

Status ImuSampleStepper::CheckGap(int64_t stamp_ns) {
  const double dt = ToSeconds(stamp_ns - stamp_ns_);
  if (dt <= max_gap_s_) return Status::Ok();
  ++num_gaps_;
  std::ostringstream os;
  os << owner_ << ": gap of " << dt << " s from " << stamp_ns_ << " ns to " << stamp_ns
     << " ns exceeds max_gap_s = " << max_gap_s_ << " s; " << gap_note_;
  return Status::OutOfRange(os.str());
}

ImuInput ImuSampleStepper::Midpoint(const ImuInput& next,
                                    int64_t next_stamp_ns,
                                    int64_t end_ns) const {
  return MidpointInput(last_input_, last_sample_.stamp_ns, next, next_stamp_ns, stamp_ns_, end_ns);
}

}  // namespace swarmlio::lio
