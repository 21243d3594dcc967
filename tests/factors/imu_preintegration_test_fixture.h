// The shared fixture of the ImuPreintegration / ImuPreintegrationFactor tests
// (imu_preintegration_*_test.cc; docs/factors.md, "IMU preintegration
// factor"): a known smooth motion and its 200 Hz IMU stream (constant body
// rate, constant acceleration in G, G not gravity aligned, nonzero biases;
// scan-end times between samples), the filter run over the same samples, the
// preintegration, and random factor problems.
#pragma once

#include "factors/imu_preintegration_factor.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "factors/ego_state_manifold.h"
#include "swarmlio/lio/imu_preintegration.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "test_utils/random_sampler.h"

namespace swarmlio::imu_preintegration_test {


using L = ErrorStateLayout;
using Matrix18 = PreintegratedImu::Matrix18;
using Vector18 = Eigen::Matrix<double, 18, 1>;

inline constexpr int64_t kImuPeriodNs = 5'000'000;  // 200 Hz

using Sampler = swarmlio::testing::RandomSampler;

// R(t) = R0 Exp(w t), v(t) = v0 + a t, p(t) = p0 + v0 t + a t^2 / 2; the IMU
// measures w + b_g and R(t)^T (a - g) + b_a, reported divided by
// acceleration_to_m_s2 (e.g. in g units).
struct Motion {
  Eigen::Quaterniond q0 = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p0, v0, w_b, a_in_G, g_in_G, b_g, b_a;
  double acceleration_to_m_s2 = 1.0;

  explicit Motion(Sampler* s)
      : q0(s->Rotation(-1.0)),
        p0(s->Gaussian3(5.0)),
        v0(s->Gaussian3(2.0)),
        w_b(s->Gaussian3(0.8)),
        a_in_G(s->Gaussian3(2.0)),
        g_in_G(9.81 * s->Axis()),
        b_g(s->Gaussian3(0.02)),
        b_a(s->Gaussian3(0.2)) {}

  Eigen::Matrix3d R(double t) const { return q0.toRotationMatrix() * so3::Exp(w_b * t); }
  EgoState State(double t) const {
    EgoState x;
    x.q_G_b = Eigen::Quaterniond(R(t));
    x.p_b_in_G = p0 + v0 * t + 0.5 * t * t * a_in_G;
    x.v_b_in_G = v0 + t * a_in_G;
    x.gyro_bias = b_g;
    x.accel_bias = b_a;
    x.g_in_G = g_in_G;
    return x;
  }
  ImuSample Sample(int64_t stamp_ns) const {
    const double t = ToSeconds(stamp_ns);
    ImuSample s;
    s.stamp_ns = stamp_ns;
    s.angular_velocity_rad_s = w_b + b_g;
    s.linear_acceleration = (R(t).transpose() * (a_in_G - g_in_G) + b_a) / acceleration_to_m_s2;
    return s;
  }
};

// The interval [t_k, t_k+1] and how its ends are reached.
struct Window {
  int64_t t_k_ns = 12'300'000;  // between samples
  int64_t t_k1_ns = 112'300'000;
  bool interpolate_ends = true;  // PropagateTo(t, &next) rather than the hold
};

// The filter: from the true state at sample 0 to t_k, where the state and
// covariance may be replaced (SetState), then to t_k+1.
struct FilterRun {
  EgoState x_k, x_k1;
  Eigen::MatrixXd P_k1;
};

inline FilterRun RunPropagator(const Motion& m,
                        const Window& w,
                        const Eigen::MatrixXd& P_k,
                        const EgoState* x_k_override = nullptr,
                        const lio::ImuPropagatorOptions& options = {}) {
  std::unique_ptr<lio::ImuPropagator> prop;
  EXPECT_TRUE(lio::ImuPropagator::Create(options, &prop).ok());
  SwarmState x0;
  x0.ego = m.State(0.0);
  EXPECT_TRUE(
      prop->Reset(x0, 1e-4 * Eigen::MatrixXd::Identity(18, 18), m.Sample(0), m.acceleration_to_m_s2)
          .ok());
  int64_t k = 1;
  const auto run_to = [&](int64_t t_ns) {
    for (; k * kImuPeriodNs <= t_ns; ++k)
      EXPECT_TRUE(prop->AddImu(m.Sample(k * kImuPeriodNs)).ok());
    const ImuSample next = m.Sample(k * kImuPeriodNs);
    EXPECT_TRUE(prop->PropagateTo(t_ns, w.interpolate_ends ? &next : nullptr).ok());
  };
  run_to(w.t_k_ns);
  SwarmState x_k = prop->state();
  if (x_k_override != nullptr) x_k.ego = *x_k_override;
  prop->SetState(x_k, P_k);
  run_to(w.t_k1_ns);
  return {x_k.ego, prop->state().ego, prop->covariance()};
}

inline lio::ImuPreintegrationOptions DefaultOptions() { return lio::ImuPreintegrationOptions(); }

// The preintegration of the same samples over [t_k, t_k+1].
inline std::unique_ptr<lio::ImuPreintegration> Preintegrate(
    const Motion& m,
    const Window& w,
    const Eigen::Vector3d& gyro_bias,
    const Eigen::Vector3d& accel_bias,
    const lio::ImuPreintegrationOptions& options = DefaultOptions()) {
  std::unique_ptr<lio::ImuPreintegration> pre;
  EXPECT_TRUE(lio::ImuPreintegration::Create(options, &pre).ok());
  int64_t k = w.t_k_ns / kImuPeriodNs;  // the last sample at or before t_k
  EXPECT_TRUE(pre->Reset(w.t_k_ns, m.Sample(k * kImuPeriodNs), m.acceleration_to_m_s2, gyro_bias,
                         accel_bias)
                  .ok());
  for (++k; k * kImuPeriodNs <= w.t_k1_ns; ++k) {
    EXPECT_TRUE(pre->AddImu(m.Sample(k * kImuPeriodNs)).ok());
  }
  const ImuSample next = m.Sample(k * kImuPeriodNs);
  EXPECT_TRUE(pre->IntegrateTo(w.t_k1_ns, w.interpolate_ends ? &next : nullptr).ok());
  return pre;
}

inline std::unique_ptr<ImuPreintegrationFactor> MakeFactor(const PreintegratedImu& m) {
  std::unique_ptr<ImuPreintegrationFactor> factor;
  const Status status = ImuPreintegrationFactor::Create(m, &factor);
  EXPECT_TRUE(status.ok()) << status.message();
  return factor;
}

// The state at t_k+1 that the (bias-corrected) preintegration predicts from x_k.
inline EgoState Predict(const PreintegratedImu& m, const EgoState& x_k) {
  const double T = m.dt_s;
  const Eigen::Matrix3d R_k = x_k.R_G_b();
  EgoState y = x_k;
  y.q_G_b = Eigen::Quaterniond(R_k * m.CorrectedDeltaR(x_k.gyro_bias));
  y.v_b_in_G =
      x_k.v_b_in_G + T * x_k.g_in_G + R_k * m.CorrectedDeltaV(x_k.gyro_bias, x_k.accel_bias);
  y.p_b_in_G = x_k.p_b_in_G + T * x_k.v_b_in_G + 0.5 * T * T * x_k.g_in_G +
               R_k * m.CorrectedDeltaP(x_k.gyro_bias, x_k.accel_bias);
  return y;
}

// blockdiag(I, R, R, I, I): p and v of the preintegration are in b_k.
inline Eigen::Matrix<double, 15, 15> BodyToGlobal(const Eigen::Matrix3d& R_k) {
  Eigen::Matrix<double, 15, 15> T = Eigen::Matrix<double, 15, 15>::Identity();
  T.block<3, 3>(L::kPosition.offset, L::kPosition.offset) = R_k;
  T.block<3, 3>(L::kVelocity.offset, L::kVelocity.offset) = R_k;
  return T;
}

// Ceres parameter storage for the two ego blocks and their manifolds.
struct Blocks {
  Blocks(const EgoState& x_k, const EgoState& x_k1) {
    x_k.ToParameters(a.data());
    x_k1.ToParameters(b.data());
  }
  std::vector<const double*> pointers() const { return {a.data(), b.data()}; }
  std::vector<const ceres::Manifold*> manifolds() const { return {&manifold, &manifold}; }
  std::array<double, 19> a, b;
  EgoStateManifold manifold;
};

// A factor from a random motion, and states (x_k, x_k+1) around it, with
// biases off the linearization point (so the bias correction is active) and
// the other parts of x_k+1 near the prediction. Rotations: x_k's by `angle_k`
// and x_k+1 near the prediction (kNear), x_k+1's by `angle_k1` and x_k near
// it (angle_k = kNear), or both independent (a large rotation residual).
inline constexpr double kNear = -2.0;

struct Problem {
  Motion motion;
  PreintegratedImu preintegrated;
  EgoState x_k, x_k1;

  Problem(Sampler* s, double angle_k, double angle_k1) : motion(s) {
    preintegrated = Preintegrate(motion, Window(), motion.b_g, motion.b_a)->preintegrated();
    x_k = motion.State(0.0123);
    x_k.gyro_bias += s->Gaussian3(0.01);
    x_k.accel_bias += s->Gaussian3(0.05);
    const Eigen::Matrix3d delta_R_c = preintegrated.CorrectedDeltaR(x_k.gyro_bias);
    const Eigen::Quaterniond q_k1 = s->Rotation(angle_k1 == kNear ? -1.0 : angle_k1);
    x_k.q_G_b = angle_k == kNear
                    ? Eigen::Quaterniond(q_k1.toRotationMatrix() *
                                         (delta_R_c * so3::Exp(s->Gaussian3(0.05))).transpose())
                    : s->Rotation(angle_k);
    Vector18 dx;
    for (int i = 0; i < 18; ++i) dx[i] = 0.05 * s->Normal();
    x_k1 = Predict(preintegrated, x_k).BoxPlus(dx);
    if (angle_k1 != kNear) x_k1.q_G_b = q_k1;
  }
};


}  // namespace swarmlio::imu_preintegration_test
