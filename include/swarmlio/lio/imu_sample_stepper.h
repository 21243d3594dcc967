// ImuSampleStepper: the IMU sample handling that the propagator (filter) and
// the preintegration (window) share, written once. It knows where the
// integration stands (stamp_ns), the last accepted sample and its input, and
// turns each new sample or target time into the step to integrate: the input
// held over the step (the midpoint interpolation of docs/imu.md) and its
// length. It integrates nothing itself; the owner integrates the step and
// then tells the stepper (Advance, Hold).
//
//   ImuStep step;
//   ImuSampleStepper::Action action;
//   Status s = stepper.Accept(sample, &action, &step);   // errors counted
//   if (!s.ok()) return s;
//   if (action == ImuSampleStepper::Action::kSkip) return Status::Ok();
//   if (action == ImuSampleStepper::Action::kStep) { Integrate(step); stepper.Advance(step); }
//   stepper.Hold(sample);                                // the new held input
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::lio {

/// IMU input in SI units and the IMU frame (sign and unit already applied).
struct ImuInput {
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  // w_m
  Eigen::Vector3d specific_force_m_s2 = Eigen::Vector3d::Zero();     // a_m
};

/// Converts a raw sample: a_m = acceleration_to_m_s2 * linear_acceleration
/// (the signed factor from ImuInitialization).
ImuInput ToImuInput(const ImuSample& sample, double acceleration_to_m_s2);

/// The input held over [from_ns, to_ns]: the linear interpolation between the
/// last sample (`last` at `last_stamp_ns`) and `next` (at `next_stamp_ns`),
/// taken at the interval's midpoint (the propagator's discrete model; the
/// preintegration uses the same function so the two agree to round-off).
ImuInput MidpointInput(const ImuInput& last,
                       int64_t last_stamp_ns,
                       const ImuInput& next,
                       int64_t next_stamp_ns,
                       int64_t from_ns,
                       int64_t to_ns);

/// One integration step: `input` held over dt_s, ending at end_ns.
struct ImuStep {
  ImuInput input;
  double dt_s = 0.0;  // [s]
  int64_t end_ns = 0;
};

class ImuSampleStepper {
 public:
  enum class Action {
    kSkip,       // duplicate or not after the current time (counted): nothing to do
    kInputOnly,  // the integration already stands at the sample's stamp: Hold() only
    kStep,       // integrate the step, Advance(), then Hold()
  };

  /// `owner` prefixes every message ("imu propagator"); `gap_note` ends the
  /// message of a refused gap (what the owner's caller should do).
  ImuSampleStepper(std::string owner, double max_gap_s, std::string gap_note);

  /// Stands at stamp_ns holding `last_sample` (at or before stamp_ns).
  void Reset(int64_t stamp_ns, const ImuSample& last_sample, double acceleration_to_m_s2);

  /// What `sample` means for the integral (see Action); `step` is set for
  /// kStep. Non-finite sample: InvalidArgument; a step longer than max_gap_s:
  /// OutOfRange. Both counted; nothing changes.
  Status Accept(const ImuSample& sample, Action* action, ImuStep* step);

  /// The step to exactly stamp_ns, holding the last input or interpolating
  /// towards `next_sample` (the first sample at or after stamp_ns, not
  /// consumed). `*needed` is false when the integration stands at stamp_ns.
  /// Earlier: OutOfRange. next_sample before stamp_ns or non-finite:
  /// InvalidArgument. Gap: OutOfRange (counted).
  Status StepTo(int64_t stamp_ns, const ImuSample* next_sample, ImuStep* step, bool* needed);

  /// The owner integrated `step`: the integration stands at its end.
  void Advance(const ImuStep& step) { stamp_ns_ = step.end_ns; }
  /// `sample` (accepted with kStep or kInputOnly) is the input from now on.
  void Hold(const ImuSample& sample);

  int64_t stamp_ns() const { return stamp_ns_; }
  const ImuSample& last_sample() const { return last_sample_; }
  const ImuInput& last_input() const { return last_input_; }
  double acceleration_to_m_s2() const { return acceleration_to_m_s2_; }

  int num_skipped_duplicate() const { return num_skipped_duplicate_; }
  int num_skipped_out_of_order() const { return num_skipped_out_of_order_; }
  int num_rejected_non_finite() const { return num_rejected_non_finite_; }
  int num_gaps() const { return num_gaps_; }

 private:
  Status CheckGap(int64_t stamp_ns);
  // Input at the midpoint of [stamp_ns_, end_ns], linear between the last
  // sample and `next` (at next_stamp_ns).
  ImuInput Midpoint(const ImuInput& next, int64_t next_stamp_ns, int64_t end_ns) const;

  std::string owner_;
  double max_gap_s_;
  std::string gap_note_;
  int64_t stamp_ns_ = 0;   // where the integration stands
  ImuSample last_sample_;  // the last accepted sample (raw units)
  ImuInput last_input_;    // its input (SI units)
  double acceleration_to_m_s2_ = 1.0;
  int num_skipped_duplicate_ = 0;
  int num_skipped_out_of_order_ = 0;
  int num_rejected_non_finite_ = 0;
  int num_gaps_ = 0;
};

}  // namespace swarmlio::lio
