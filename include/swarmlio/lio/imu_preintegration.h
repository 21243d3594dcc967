// ImuPreintegration: on-manifold preintegration (Forster et al., T-RO 2017)
// of the IMU samples between two scan-end times t_k and t_k+1, for the
// ImuPreintegrationFactor of the fixed-lag window (docs/factors.md, "IMU
// preintegration factor").
//
// The discrete model is ImuPropagator's, step for step (docs/imu.md): the
// same midpoint input between samples, the same interpolation at both ends of
// [t_k, t_k+1], the same per-interval update. The Deltas ARE the propagator
// run from the state (R, p, v, b_g, b_a, g) = (I, 0, 0, bg_bar, ba_bar, 0)
// with PropagateEgo:
//
//   w = w_m - bg_bar,  a = a_m - ba_bar,  phi = w dt,  M = Exp(phi / 2)
//   DeltaR' = DeltaR Exp(phi)
//   Deltav' = Deltav + DeltaR M a dt
//   Deltap' = Deltap + Deltav dt + 1/2 DeltaR M a dt^2
//
// so that R_k+1 = R_k DeltaR, v_k+1 = v_k + g T + R_k Deltav and p_k+1 = p_k +
// v_k T + 1/2 g T^2 + R_k Deltap reproduce the propagator exactly (to
// round-off) for any state at t_k: the gravity terms sum exactly, because
// sum (t_i dt_i + dt_i^2 / 2) = T^2 / 2.
//
// Per interval, with the propagator's F and G (EgoProcessJacobians, rows and
// columns [dtheta dp dv dbg dba], gravity dropped) at that pseudo state:
//   Phi' = F Phi          (Phi_0 = I; its bias columns are the bias Jacobians)
//   P'   = F P F^T + G Q G^T   (P_0 = 0; Q from ProcessNoiseOptions)
// P is the joint covariance of the preintegration errors and of the bias
// random walks over [t_k, t_k+1], equal to the propagator's covariance
// propagated from P = 0 at R_k = I (and, at any R_k, after rotating the p and
// v rows and columns by R_k).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "factors/imu_preintegration_factor.h"
#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/process_noise_options.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::lio {

struct ImuPreintegrationOptions {
  /// The filter's process noise (same meaning: variance per IMU interval,
  /// docs/imu.md). The four IMU variances must be > 0; teammate entries are unused.
  ProcessNoiseOptions process_noise;
  double max_gap_s = 0.1;  // a larger step between inputs is refused [s]
  /// Standard deviation of g_k+1 - g_k in the factor [m/s^2]: g is constant
  /// (zero process noise), this small floor keeps the covariance positive definite.
  double gravity_stddev_floor_m_s2 = 1e-4;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("process_noise", process_noise);
    v("max_gap_s", max_gap_s,
      FieldSpec::Positive("s", "largest IMU interval that is integrated").WithMax(10.0));
    v("gravity_stddev_floor_m_s2", gravity_stddev_floor_m_s2,
      FieldSpec::Positive("m/s^2", "stddev of the gravity change between two window states")
          .WithMax(1.0));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const;
};

/// Preintegrates one interval [t_k, t_k+1] (or, with Restart(), a sequence of
/// consecutive intervals). Same sample handling as ImuPropagator.
class ImuPreintegration {
 public:
  using Matrix15 = Eigen::Matrix<double, 15, 15>;

  /// InvalidArgument when `options` do not validate.
  static Status Create(const ImuPreintegrationOptions& options,
                       std::unique_ptr<ImuPreintegration>* preintegration);

  /// Starts at t_k = start_stamp_ns with the linearization biases (the
  /// estimate at t_k). `last_sample` is the last IMU sample at or before t_k
  /// (the input the propagator holds at t_k); acceleration_to_m_s2 is the
  /// signed unit factor (ImuInitialization). InvalidArgument when the sample
  /// is after start_stamp_ns or anything is non-finite.
  Status Reset(int64_t start_stamp_ns,
               const ImuSample& last_sample,
               double acceleration_to_m_s2,
               const Eigen::Vector3d& gyro_bias,
               const Eigen::Vector3d& accel_bias);

  /// As ImuPropagator::AddImu: integrates to sample.stamp_ns with the
  /// midpoint input; duplicates and stamps not after the current time are
  /// skipped and counted (Ok); non-finite: InvalidArgument; a step longer than
  /// max_gap_s: OutOfRange (nothing changes).
  Status AddImu(const ImuSample& sample);

  /// As ImuPropagator::PropagateTo: integrates to exactly stamp_ns (t_k+1),
  /// holding the last sample, or interpolating towards `next_sample` (the
  /// first sample at or after stamp_ns, not consumed).
  Status IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample = nullptr);

  /// Starts the next interval at the current time (t_k+1 becomes t_k) with
  /// new linearization biases, keeping the last sample (as StartScan()).
  void Restart(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias);

  /// Integrates the stored inputs of the current interval again with new
  /// linearization biases (when the estimate moved too far from them for the
  /// first-order correction).
  void Reintegrate(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias);

  /// The current interval [start_stamp_ns(), stamp_ns()], covariance in the
  /// factor's 18x18 residual order (gravity floor included).
  const PreintegratedImu& preintegrated() const { return preintegrated_; }
  /// P (15x15, [dtheta dp dv dbg dba]) without the gravity floor.
  const Matrix15& covariance() const { return covariance_; }

  int64_t start_stamp_ns() const { return start_stamp_ns_; }
  int64_t stamp_ns() const { return stepper_.stamp_ns(); }
  bool initialized() const { return initialized_; }
  /// Integration steps of the current interval.
  int num_intervals() const { return static_cast<int>(steps_.size()); }
  /// Sum of the squared step lengths of the current interval [s^2]: the
  /// propagator's teammate random walk over the interval is this times the
  /// teammate variances (docs/imu.md).
  double SumOfSquaredSteps() const;

  int num_skipped_duplicate() const { return stepper_.num_skipped_duplicate(); }
  int num_skipped_out_of_order() const { return stepper_.num_skipped_out_of_order(); }
  int num_rejected_non_finite() const { return stepper_.num_rejected_non_finite(); }
  int num_gaps() const { return stepper_.num_gaps(); }

 private:
  struct Step {
    ImuInput input;  // the (midpoint) input integrated over the step
    double dt_s = 0.0;
  };

  explicit ImuPreintegration(const ImuPreintegrationOptions& options)
      : options_(options),
        Q_(EgoNoiseCovariance(options.process_noise)),
        stepper_("imu preintegration", options.max_gap_s, "not integrated") {}

  // Resets the Deltas, Phi and P to the start of the interval.
  void ClearIntegral(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias);
  // One step of the model, Phi and P; does not record it.
  void Integrate(const Step& step);
  // Integrates, records the step and ends at its end.
  void Advance(const ImuStep& step);
  // Copies the integral into preintegrated_.
  void Publish();

  ImuPreintegrationOptions options_;
  Eigen::Matrix<double, ImuNoiseLayout::kDim, ImuNoiseLayout::kDim> Q_;  // per IMU interval
  bool initialized_ = false;
  ImuSampleStepper stepper_;  // time, last sample and input, sample counters
  int64_t start_stamp_ns_ = 0;
  // The integral as a propagator state: (DeltaR, Deltap, Deltav, bg_bar, ba_bar, g = 0).
  EgoState delta_;
  Matrix15 transition_ = Matrix15::Identity();  // Phi
  Matrix15 covariance_ = Matrix15::Zero();      // P
  std::vector<Step> steps_;
  PreintegratedImu preintegrated_;
};

}  // namespace swarmlio::lio
