// lio::Odometry's in-flight initialization (docs/imu.md section 1b).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "odometry_impl.h"

namespace swarmlio::lio {
namespace {

using L = ErrorStateLayout;

// The counters as they were before the probe's passes (which leave no trace),
// with the input counters and the in-flight ones of `now`.
OdometryCounters ProbeCountersWithInput(const OdometryCounters& before_probe,
                                        const OdometryCounters& now) {
  OdometryCounters c = before_probe;
  c.imu_samples = now.imu_samples;
  c.imu_rejected = now.imu_rejected;
  c.imu_out_of_order = now.imu_out_of_order;
  c.scans = now.scans;
  c.scans_empty = now.scans_empty;
  c.scans_before_init = now.scans_before_init;
  c.scans_dropped_queue = now.scans_dropped_queue;
  c.in_flight_passes = now.in_flight_passes;
  c.in_flight_restarts = now.in_flight_restarts;
  return c;
}

// The initial state of the next pass from the fit: v0 and g with their
// covariance, the coarse start's other blocks (rotation, position, gyro-bias
// prior), and the b_a prior with the g - b_a correlation of a static start
// (the fit assumed b_a = 0, so its g absorbed R_G_b b_a: equal errors).
ImuInitialization FromAlignment(const ImuInitialization& coarse,
                                const VelocityGravityAlignment& fit,
                                const InFlightInitOptions& options,
                                double accel_bias_sigma) {
  ImuInitialization next = coarse;
  next.state.v_b_in_G = fit.v_b_in_G;
  next.state.g_in_G = fit.g_in_G;
  next.gravity_magnitude_m_s2 = fit.g_in_G.norm();
  next.alignment_num_poses = fit.num_positions;
  next.alignment_rms_m = fit.rms_residual_m;
  auto& P = next.covariance;
  const int v = L::kVelocity.offset;
  const int g = L::kGravity.offset;
  const int ba = L::kAccelBias.offset;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double sv = options.velocity_stddev_floor_m_s;
  const double sg = options.gravity_stddev_floor_m_s2;
  const double sba2 = accel_bias_sigma * accel_bias_sigma;
  P.block<3, 3>(v, v) = fit.covariance.block<3, 3>(0, 0) + sv * sv * I;
  P.block<3, 3>(g, g) = fit.covariance.block<3, 3>(3, 3) + (sg * sg + sba2) * I;
  P.block<3, 3>(v, g) = fit.covariance.block<3, 3>(0, 3);
  P.block<3, 3>(g, v) = fit.covariance.block<3, 3>(3, 0);
  P.block<3, 3>(g, ba) = sba2 * I;
  P.block<3, 3>(ba, g) = sba2 * I;
  return next;
}

}  // namespace

void Odometry::StartInFlightProbe(const ImuInitialization& coarse) {
  internal::InFlightProbe& probe = impl_->probe;
  probe = internal::InFlightProbe();
  probe.active = true;
  probe.start = coarse;
  probe.counters = counters_;
  impl_->static_start_scans.clear();
  init_error_ = "in-flight initialization: pass 1 of " + std::to_string(options_.in_flight.passes);
}

void Odometry::FinishInFlightPass() {
  Impl& im = *impl_;
  internal::InFlightProbe& probe = im.probe;
  const ImuInitialization& start = probe.start;
  VelocityGravityAlignment fit;
  // The pass's b_g (the filter estimated it from the LiDAR rotations) both
  // integrates between the scans here and starts the next pass.
  Status status = AlignVelocityAndGravity(start.last_sample, probe.imu, start.acceleration_to_m_s2,
                                          probe.gyro_bias, probe.positions,
                                          options_.in_flight.position_stddev_floor_m, &fit);
  ++counters_.in_flight_passes;
  const double g0 = options_.imu_init.nominal_gravity_m_s2;
  if (status.ok() && !(fit.rms_residual_m <= options_.in_flight.max_rms_residual_m)) {
    std::ostringstream os;
    os << "in-flight initialization: the fit's rms residual " << fit.rms_residual_m
       << " m exceeds in_flight.max_rms_residual_m " << options_.in_flight.max_rms_residual_m;
    status = Status::FailedPrecondition(os.str());
  }
  if (status.ok() &&
      !(std::abs(fit.g_in_G.norm() / g0 - 1.0) <= options_.imu_init.max_gravity_error_ratio)) {
    std::ostringstream os;
    os << "in-flight initialization: fitted |g| = " << fit.g_in_G.norm() << " m/s^2 is not within "
       << options_.imu_init.max_gravity_error_ratio * 100 << " % of " << g0 << " m/s^2";
    status = Status::FailedPrecondition(os.str());
  }
  if (!status.ok()) {
    // Start over: a new IMU window, then a new coarse start.
    counters_ = ProbeCountersWithInput(probe.counters, counters_);
    ++counters_.in_flight_restarts;
    probe = internal::InFlightProbe();
    im.initialized = false;
    im.imu_queue.clear();
    im.input.ClearScans();
    im.map = LocalMap(options_.map);
    im.have_anchor = false;
    im.initializer->Reset();
    im.previous_degenerate = false;
    init_error_ = status.message();
    return;
  }
  ImuInitialization next = FromAlignment(start, fit, options_.in_flight,
                                         options_.imu_init.initial_accel_bias_stddev_m_s2);
  next.state.gyro_bias = probe.gyro_bias;
  ++probe.pass;
  next.alignment_passes = probe.pass;
  const bool last = probe.pass >= options_.in_flight.passes;
  const Status restarted = RestartFromInFlightStart(next);
  if (!restarted.ok()) {
    init_error_ = restarted.message();
    return;
  }
  probe.start = next;
  probe.positions.clear();
  if (!last) {
    init_error_ = "in-flight initialization: pass " + std::to_string(probe.pass + 1) + " of " +
                  std::to_string(options_.in_flight.passes);
    return;
  }
  // The odometry proper starts: the probe's processing leaves no trace in
  // the counters (its input counters stay).
  counters_ = ProbeCountersWithInput(probe.counters, counters_);
  im.initialization = next;
  im.initialization.started_ns = im.input.newest_imu_ns();  // the newest input
  probe = internal::InFlightProbe();
  init_error_.clear();
}

Status Odometry::RestartFromInFlightStart(const ImuInitialization& start) {
  Impl& im = *impl_;
  SWARMLIO_RETURN_IF_ERROR(im.propagator->Reset(start));
  im.map = LocalMap(options_.map);
  im.have_anchor = false;
  SWARMLIO_RETURN_IF_ERROR(CreateBackEnd());
  im.imu_queue.assign(im.probe.imu.begin(), im.probe.imu.end());
  im.input.ReplayScans(im.probe.scans);
  im.previous_degenerate = false;
  return Status::Ok();
}

}  // namespace swarmlio::lio
