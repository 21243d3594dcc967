// IMU state and covariance prediction (paper Sec. III-D, eq. (2)-(3);
// the math, F, G and Q are written out in docs/imu.md).
//
// Discrete model for one interval [t_k, t_k + dt] with the input u = (w_m,
// a_m) held constant (the MIDPOINT of the two bounding samples, or the last
// sample when propagating to a time before the next sample arrives):
//
//   w   = w_m - b_g - n_g                 a  = a_m - b_a - n_a
//   R'  = R Exp(w dt)
//   a_G = R Exp(w dt / 2) a + g           (acceleration at the midpoint attitude)
//   p'  = p + v dt + a_G dt^2 / 2         v' = v + a_G dt
//   b_g' = b_g + n_bg dt   b_a' = b_a + n_ba dt   g' = g
//   teammate blocks: R_Gi_Gj' = R_Gi_Gj Exp(n_R dt),  p_Gj_in_Gi' = p_Gj_in_Gi + n_p dt
//
// This is eq. (2) with the rotation and velocity integrated to second order
// (eq. (2) taken literally, p' = p + v dt, is first order and drifts by
// ~ |a| dt T / 2, i.e. centimetres over 2 s at 200 Hz).
// Covariance: P' = F P F^T + G Q G^T, F = d x' / d x, G = d x' / d w in the
// right-perturbation error state (ErrorStateLayout), Q from
// ProcessNoiseOptions. Teammate blocks are identity in F.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_sample_stepper.h"
#include "swarmlio/lio/process_noise_options.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/state_layout.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

struct ImuInitialization;

/// Order of the ego process-noise vector w = [n_g n_a n_bg n_ba].
struct ImuNoiseLayout {
  static constexpr Segment kGyro{0, 3};           // n_g  [rad/s]
  static constexpr Segment kAccel{3, 3};          // n_a  [m/s^2]
  static constexpr Segment kGyroBiasWalk{6, 3};   // n_bg [rad/s^2]
  static constexpr Segment kAccelBiasWalk{9, 3};  // n_ba [m/s^3]
  static constexpr int kDim = 12;
};

using EgoMatrix = Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim>;
using EgoNoiseMatrix = Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ImuNoiseLayout::kDim>;
using ImuNoiseVector = Eigen::Matrix<double, ImuNoiseLayout::kDim, 1>;

/// One step of the discrete model above (ego part) with noise w.
EgoState PropagateEgo(const EgoState& x,
                      const ImuInput& u,
                      double dt_s,
                      const ImuNoiseVector& w = ImuNoiseVector::Zero());

/// F = d x' / d x (18x18) and G = d x' / d w (18x12) at (x, u, w = 0).
void EgoProcessJacobians(
    const EgoState& x, const ImuInput& u, double dt_s, EgoMatrix* F, EgoNoiseMatrix* G);

/// Q of the ego noise vector (ImuNoiseLayout order), variances per interval.
Eigen::Matrix<double, ImuNoiseLayout::kDim, ImuNoiseLayout::kDim> EgoNoiseCovariance(
    const ProcessNoiseOptions& noise);

/// The body state at one instant of the current scan and the unbiased input
/// held from this instant to the next one (for motion compensation).
struct ImuPose {
  int64_t stamp_ns = 0;
  Eigen::Matrix3d R_G_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_b_in_G = Eigen::Vector3d::Zero();  // [m]
  Eigen::Vector3d v_b_in_G = Eigen::Vector3d::Zero();  // [m/s]
  Eigen::Vector3d acc_in_G_m_s2 =
      Eigen::Vector3d::Zero();  // a_G (gravity included) until the next pose
  Eigen::Vector3d angular_velocity_in_b_rad_s = Eigen::Vector3d::Zero();  // w until the next pose
};

struct ImuPropagatorOptions {
  ProcessNoiseOptions process_noise;
  double max_gap_s = 0.1;  // a larger step between inputs is refused [s]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("process_noise", process_noise);
    config::VisitExperimental(v, [&](auto& x) {
      x("max_gap_s", max_gap_s,
        FieldSpec::Positive("s", "largest IMU interval that is propagated").WithMax(10.0));
    });
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// Propagates a SwarmState (ego by the IMU, teammates by their random walk)
/// and its covariance (dimension state.Dim()) from IMU sample to IMU sample,
/// and records the per-sample poses of the current scan.
class ImuPropagator {
 public:
  /// InvalidArgument when `options` do not validate.
  static Status Create(const ImuPropagatorOptions& options,
                       std::unique_ptr<ImuPropagator>* propagator);

  /// Starts at `state` (covariance P, Dim() x Dim()) at the time of `sample`,
  /// which is the input at that time; acceleration_to_m_s2 is the signed unit
  /// factor. Clears the scan poses and starts a new scan there.
  Status Reset(const SwarmState& state,
               const Eigen::MatrixXd& P,
               const ImuSample& sample,
               double acceleration_to_m_s2);
  /// Reset() from an initialization (no teammates).
  Status Reset(const ImuInitialization& init);

  /// Propagates from the current time to sample.stamp_ns with the midpoint
  /// of the previous input and this sample. Stamps not after the current
  /// time are skipped and counted (Ok). Non-finite sample: InvalidArgument.
  /// A step longer than max_gap_s: OutOfRange, nothing changes (re-initialize).
  Status AddImu(const ImuSample& sample);

  /// Propagates to exactly stamp_ns (e.g. the scan end). Without
  /// `next_sample` the last sample's input is held (zero-order hold, first
  /// order over the remainder); with the first sample at or after stamp_ns
  /// (not consumed: pass it to AddImu() afterwards) the input is linearly
  /// interpolated at the midpoint of the remainder (second order).
  /// stamp_ns == stamp_ns(): no-op. Earlier: OutOfRange. next_sample before
  /// stamp_ns or non-finite: InvalidArgument. Gap: OutOfRange.
  Status PropagateTo(int64_t stamp_ns, const ImuSample* next_sample = nullptr);

  /// Starts a new scan: the pose buffer restarts with the current state.
  void StartScan();

  /// Replaces state and covariance (after an update; the layout may differ
  /// from before). Time and last input are kept; the scan poses restart at
  /// the new state (as StartScan()).
  void SetState(const SwarmState& state, const Eigen::MatrixXd& P);

  const SwarmState& state() const { return state_; }
  const Eigen::MatrixXd& covariance() const { return P_; }
  int64_t stamp_ns() const { return stepper_.stamp_ns(); }
  /// The last accepted IMU sample (raw units): the input held at stamp_ns()
  /// (the window smoother's preintegration starts from it).
  const ImuSample& last_sample() const { return stepper_.last_sample(); }
  bool initialized() const { return initialized_; }
  /// Poses of the current scan: the state at StartScan(), then one per
  /// propagation step (IMU samples, then the PropagateTo() target).
  const std::vector<ImuPose>& scan_poses() const { return scan_poses_; }

  int num_skipped_duplicate() const { return stepper_.num_skipped_duplicate(); }
  int num_skipped_out_of_order() const { return stepper_.num_skipped_out_of_order(); }
  int num_rejected_non_finite() const { return stepper_.num_rejected_non_finite(); }
  int num_gaps() const { return stepper_.num_gaps(); }

 private:
  explicit ImuPropagator(const ImuPropagatorOptions& options)
      : options_(options),
        stepper_("imu propagator", options.max_gap_s, "not propagated (re-initialize)") {}

  // Propagates over the step and appends a scan pose at its end.
  void Step(const ImuStep& step);
  void PropagateCovariance(const EgoMatrix& F, const EgoNoiseMatrix& G, double dt_s);
  ImuPose CurrentPose(const ImuInput& u) const;

  ImuPropagatorOptions options_;
  bool initialized_ = false;
  SwarmState state_;
  Eigen::MatrixXd P_;
  ImuSampleStepper stepper_;  // time, last sample and input, sample counters
  std::vector<ImuPose> scan_poses_;
};

}  // namespace swarmlio::lio
