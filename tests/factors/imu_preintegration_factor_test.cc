// ImuPreintegration and ImuPreintegrationFactor (docs/factors.md, "IMU
// preintegration factor"). The IMU streams come from a known smooth motion
// (constant body rate, constant acceleration in G, G not gravity aligned,
// nonzero biases, 200 Hz) and the scan-end times fall between samples. Checks:
// the residual is zero where ImuPropagator lands (every end-point variant),
// the covariance equals the propagator's from P = 0, a one-state window
// reproduces the filter's covariance, the first-order bias correction against
// re-preintegration, the bias Jacobians and the factor's manifold Jacobians
// against numeric differentiation (random, near-identity and near-pi
// rotations) and that the check rejects flipped signs, plus option and
// input errors.
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

namespace swarmlio {
namespace {

using L = ErrorStateLayout;
using Matrix18 = PreintegratedImu::Matrix18;
using Vector18 = Eigen::Matrix<double, 18, 1>;

constexpr int64_t kImuPeriodNs = 5'000'000;  // 200 Hz

class Sampler {
 public:
  explicit Sampler(unsigned seed) : rng_(seed) {}
  double Normal() { return n_(rng_); }
  Eigen::Vector3d Gaussian3(double scale) {
    return scale * Eigen::Vector3d(Normal(), Normal(), Normal());
  }
  Eigen::Vector3d Axis() { return Gaussian3(1.0).normalized(); }
  // Rotation by `angle` about a random axis (uniformly random when < 0).
  Eigen::Quaterniond Rotation(double angle) {
    if (angle < 0) {
      return Eigen::Quaterniond(
          Eigen::Vector4d(Normal(), Normal(), Normal(), Normal()).normalized());
    }
    return so3::ExpQuaternion(Axis() * angle);
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> n_;
};

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
    const double t = StampSeconds(stamp_ns);
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

FilterRun RunPropagator(const Motion& m,
                        const Window& w,
                        const Eigen::MatrixXd& P_k,
                        const EgoState* x_k_override = nullptr,
                        const ImuPropagatorOptions& options = {}) {
  std::unique_ptr<ImuPropagator> prop;
  EXPECT_TRUE(ImuPropagator::Create(options, &prop).ok());
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

ImuPreintegrationOptions DefaultOptions() { return ImuPreintegrationOptions(); }

// The preintegration of the same samples over [t_k, t_k+1].
std::unique_ptr<ImuPreintegration> Preintegrate(
    const Motion& m,
    const Window& w,
    const Eigen::Vector3d& gyro_bias,
    const Eigen::Vector3d& accel_bias,
    const ImuPreintegrationOptions& options = DefaultOptions()) {
  std::unique_ptr<ImuPreintegration> pre;
  EXPECT_TRUE(ImuPreintegration::Create(options, &pre).ok());
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

std::unique_ptr<ImuPreintegrationFactor> MakeFactor(const PreintegratedImu& m) {
  std::unique_ptr<ImuPreintegrationFactor> factor;
  const Status status = ImuPreintegrationFactor::Create(m, &factor);
  EXPECT_TRUE(status.ok()) << status.message();
  return factor;
}

// The state at t_k+1 that the (bias-corrected) preintegration predicts from x_k.
EgoState Predict(const PreintegratedImu& m, const EgoState& x_k) {
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
Eigen::Matrix<double, 15, 15> BodyToGlobal(const Eigen::Matrix3d& R_k) {
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
constexpr double kNear = -2.0;

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

// --- (c) the residual is zero where the propagator lands -------------------

TEST(ImuPreintegrationFactor, ResidualIsZeroWhereThePropagatorLands) {
  Sampler s(1);
  std::vector<Window> windows(4);
  windows[1].interpolate_ends = false;   // zero-order hold at both ends
  windows[2].t_k_ns = 4 * kImuPeriodNs;  // both ends on samples
  windows[2].t_k1_ns = 24 * kImuPeriodNs;
  windows[3].t_k_ns = 7 * kImuPeriodNs + 1;  // 1 ns after a sample, 0.5 s long
  windows[3].t_k1_ns = 107 * kImuPeriodNs - 1;
  for (size_t i = 0; i < windows.size(); ++i) {
    for (double acceleration_to_m_s2 : {1.0, -9.81}) {
      SCOPED_TRACE(::testing::Message() << "window " << i << ", unit " << acceleration_to_m_s2);
      Motion m(&s);
      m.acceleration_to_m_s2 = acceleration_to_m_s2;
      const Window& w = windows[i];
      const FilterRun run = RunPropagator(m, w, 1e-4 * Eigen::MatrixXd::Identity(18, 18));
      // The propagator follows the motion closely (sanity), ...
      EXPECT_LT(run.x_k1.BoxMinus(m.State(StampSeconds(w.t_k1_ns))).norm(), 1e-3);
      // ... and the preintegration agrees with it to round-off.
      const auto pre = Preintegrate(m, w, run.x_k.gyro_bias, run.x_k.accel_bias);
      EXPECT_EQ(pre->preintegrated().dt_s, StampSeconds(w.t_k1_ns - w.t_k_ns));
      const auto factor = MakeFactor(pre->preintegrated());
      const Vector18 e = factor->Error(run.x_k, run.x_k1);
      const Vector18 r = factor->Residual(run.x_k, run.x_k1);
      EXPECT_LT(e.norm(), 1e-11) << e.transpose();
      EXPECT_LT(r.norm(), 1e-9) << r.transpose();
      // The same through Ceres's interface.
      const Blocks b(run.x_k, run.x_k1);
      Vector18 r_ceres;
      ASSERT_TRUE(factor->Evaluate(b.pointers().data(), r_ceres.data(), nullptr));
      EXPECT_EQ(r_ceres, r);
      // A wrong end state is not zero: 1 cm in position.
      EgoState moved = run.x_k1;
      moved.p_b_in_G.x() += 0.01;
      EXPECT_GT(factor->Error(run.x_k, moved).norm(), 0.9e-2);
    }
  }
}

TEST(ImuPreintegration, RestartChainsConsecutiveIntervals) {
  Sampler s(2);
  const Motion m(&s);
  Window first;
  Window second;
  second.t_k_ns = first.t_k1_ns;
  second.t_k1_ns = 211'700'000;
  // One object: [t_k, t_k+1], Restart(), [t_k+1, t_k+2].
  std::unique_ptr<ImuPreintegration> pre;
  ASSERT_TRUE(ImuPreintegration::Create(DefaultOptions(), &pre).ok());
  int64_t k = first.t_k_ns / kImuPeriodNs;
  ASSERT_TRUE(pre->Reset(first.t_k_ns, m.Sample(k * kImuPeriodNs), 1.0, m.b_g, m.b_a).ok());
  for (const Window* w : {&first, &second}) {
    if (w == &second) pre->Restart(m.b_g, m.b_a);
    for (++k; k * kImuPeriodNs <= w->t_k1_ns; ++k) {
      ASSERT_TRUE(pre->AddImu(m.Sample(k * kImuPeriodNs)).ok());
    }
    const ImuSample next = m.Sample(k * kImuPeriodNs);
    ASSERT_TRUE(pre->IntegrateTo(w->t_k1_ns, &next).ok());
    --k;  // `next` is fed again by the next interval
    EXPECT_EQ(pre->start_stamp_ns(), w->t_k_ns);
    EXPECT_EQ(pre->stamp_ns(), w->t_k1_ns);
  }
  // The second interval equals a fresh preintegration of it.
  const auto fresh = Preintegrate(m, second, m.b_g, m.b_a);
  const PreintegratedImu& a = pre->preintegrated();
  const PreintegratedImu& b = fresh->preintegrated();
  EXPECT_EQ(a.dt_s, b.dt_s);
  EXPECT_LT((a.delta_R - b.delta_R).norm(), 1e-14);
  EXPECT_LT((a.delta_v - b.delta_v).norm(), 1e-14);
  EXPECT_LT((a.delta_p - b.delta_p).norm(), 1e-14);
  EXPECT_LT((a.covariance - b.covariance).norm(), 1e-14 * b.covariance.norm());
  EXPECT_EQ(pre->num_intervals(), fresh->num_intervals());
}

// --- (e) the covariance is the propagator's from P = 0 ---------------------

TEST(ImuPreintegration, CovarianceIsThePropagatorsFromZero) {
  Sampler s(3);
  for (bool identity_attitude : {true, false}) {
    SCOPED_TRACE(identity_attitude ? "R_k = I" : "random R_k");
    const Motion m(&s);
    const Window w;
    EgoState x_k = m.State(StampSeconds(w.t_k_ns));
    if (identity_attitude) x_k.q_G_b.setIdentity();
    const FilterRun run = RunPropagator(m, w, Eigen::MatrixXd::Zero(18, 18), &x_k);
    const auto pre = Preintegrate(m, w, x_k.gyro_bias, x_k.accel_bias);
    // Express the preintegration's p, v errors (in b_k) in G.
    const Eigen::Matrix<double, 15, 15> T = BodyToGlobal(x_k.R_G_b());
    const Eigen::Matrix<double, 15, 15> expected = T * pre->covariance() * T.transpose();
    const Eigen::MatrixXd actual = run.P_k1.topLeftCorner(15, 15);
    const double scale = actual.cwiseAbs().maxCoeff();
    EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-9 * scale)
        << "propagator\n"
        << actual << "\npreintegration\n"
        << expected;
    // Gravity is constant: no covariance in the propagator's g rows.
    EXPECT_EQ(run.P_k1.bottomRows(3).cwiseAbs().maxCoeff(), 0.0);
    // The factor's covariance is P plus the gravity floor.
    const Matrix18& S = pre->preintegrated().covariance;
    const double floor = DefaultOptions().gravity_stddev_floor_m_s2;
    Matrix18 expected_S = Matrix18::Zero();
    expected_S.topLeftCorner(15, 15) = pre->covariance();
    expected_S.bottomRightCorner(3, 3) = floor * floor * Eigen::Matrix3d::Identity();
    EXPECT_EQ(S, expected_S);
  }
}

// A window of one state (the filter's prior on x_k plus the factor, solved
// at the propagated x_k+1) has the filter's covariance at x_k+1.
TEST(ImuPreintegrationFactor, OneStateWindowReproducesTheFilterCovariance) {
  Sampler s(4);
  const Motion m(&s);
  const Window w;
  Eigen::Matrix<double, 18, 18> A;
  for (int i = 0; i < 18 * 18; ++i) A.data()[i] = 0.03 * s.Normal();
  const Eigen::MatrixXd P_k = A * A.transpose() + 1e-4 * Matrix18::Identity();
  const FilterRun run = RunPropagator(m, w, P_k);
  const auto pre = Preintegrate(m, w, run.x_k.gyro_bias, run.x_k.accel_bias);
  const auto factor = MakeFactor(pre->preintegrated());
  Matrix18 J_k, J_k1;
  factor->TangentJacobian(run.x_k, run.x_k1, &J_k, &J_k1);
  Eigen::Matrix<double, 18, 36> J;
  J << J_k, J_k1;
  Eigen::Matrix<double, 36, 36> H = J.transpose() * J;
  H.topLeftCorner<18, 18>() += P_k.inverse();
  const Matrix18 P_window = H.inverse().bottomRightCorner<18, 18>();
  Matrix18 expected = run.P_k1;
  const double floor = DefaultOptions().gravity_stddev_floor_m_s2;
  expected.block<3, 3>(15, 15) += floor * floor * Eigen::Matrix3d::Identity();
  const double scale = expected.cwiseAbs().maxCoeff();
  EXPECT_LT((P_window - expected).cwiseAbs().maxCoeff(), 1e-8 * scale) << "window\n"
                                                                       << P_window << "\nfilter\n"
                                                                       << expected;
}

// --- (d) first-order bias correction ---------------------------------------

TEST(ImuPreintegration, BiasCorrectionIsFirstOrderAccurate) {
  Sampler s(5);
  const Motion m(&s);
  Window w;
  w.t_k1_ns = w.t_k_ns + 300'000'000;  // 0.3 s
  const auto pre = Preintegrate(m, w, m.b_g, m.b_a);
  const PreintegratedImu at_b = pre->preintegrated();
  const Eigen::Vector3d dbg = s.Gaussian3(0.01);
  const Eigen::Vector3d dba = s.Gaussian3(0.1);
  double previous_error = 0.0;
  for (double scale : {1.0, 0.5, 0.25}) {
    SCOPED_TRACE(scale);
    const Eigen::Vector3d bg = m.b_g + scale * dbg;
    const Eigen::Vector3d ba = m.b_a + scale * dba;
    pre->Reintegrate(bg, ba);
    const PreintegratedImu& again = pre->preintegrated();
    const Eigen::Vector3d e_R = so3::Log(again.delta_R.transpose() * at_b.CorrectedDeltaR(bg));
    const Eigen::Vector3d e_v = at_b.CorrectedDeltaV(bg, ba) - again.delta_v;
    const Eigen::Vector3d e_p = at_b.CorrectedDeltaP(bg, ba) - again.delta_p;
    // The correction captures the change to first order ...
    const double change = so3::Log(at_b.delta_R.transpose() * again.delta_R).norm() +
                          (again.delta_v - at_b.delta_v).norm() +
                          (again.delta_p - at_b.delta_p).norm();
    const double error = e_R.norm() + e_v.norm() + e_p.norm();
    EXPECT_LT(error, 1e-2 * change);
    // ... and what is left is second order: a quarter per halving.
    if (previous_error > 0.0) {
      EXPECT_NEAR(previous_error / error, 4.0, 0.5);
    }
    previous_error = error;
    // The factor at states with these biases: corrected vs re-preintegrated.
    EgoState x_k = m.State(StampSeconds(w.t_k_ns));
    x_k.gyro_bias = bg;
    x_k.accel_bias = ba;
    const EgoState x_k1 = Predict(again, x_k);
    const auto corrected = MakeFactor(at_b);
    EXPECT_LT(corrected->Error(x_k, x_k1).norm(), 2.0 * error);
    EXPECT_LT(MakeFactor(again)->Error(x_k, x_k1).norm(), 1e-12);
  }
  // Reintegrate at the original biases restores the original integral.
  pre->Reintegrate(m.b_g, m.b_a);
  EXPECT_EQ(pre->preintegrated().delta_p, at_b.delta_p);
  EXPECT_EQ(pre->preintegrated().covariance, at_b.covariance);
}

TEST(ImuPreintegration, BiasJacobiansMatchNumericDifferentiation) {
  Sampler s(6);
  const Motion m(&s);
  Window w;
  w.t_k1_ns = w.t_k_ns + 200'000'000;
  const auto pre = Preintegrate(m, w, m.b_g, m.b_a);
  const PreintegratedImu at_b = pre->preintegrated();
  const Eigen::MatrixXd numeric = testing::NumericJacobian(
      [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        pre->Reintegrate(m.b_g + d.head<3>(), m.b_a + d.tail<3>());
        const PreintegratedImu& p = pre->preintegrated();
        Eigen::VectorXd out(9);
        out << so3::Log(at_b.delta_R.transpose() * p.delta_R), p.delta_p - at_b.delta_p,
            p.delta_v - at_b.delta_v;
        return out;
      },
      6, 1e-5);
  Eigen::Matrix<double, 9, 6> analytic = Eigen::Matrix<double, 9, 6>::Zero();
  analytic.block<3, 3>(0, 0) = at_b.dR_dbg;
  analytic.block<3, 3>(3, 0) = at_b.dp_dbg;
  analytic.block<3, 3>(3, 3) = at_b.dp_dba;
  analytic.block<3, 3>(6, 0) = at_b.dv_dbg;
  analytic.block<3, 3>(6, 3) = at_b.dv_dba;
  EXPECT_TRUE(testing::MatricesNear(analytic, numeric, 1e-8, 1e-7));
  // Flipped-sign control for this comparison.
  Eigen::Matrix<double, 9, 6> flipped = analytic;
  flipped.block<3, 3>(6, 0) *= -1.0;
  EXPECT_FALSE(testing::MatricesNear(flipped, numeric, 1e-8, 1e-7));
}

// --- (a), (b) manifold Jacobians ------------------------------------------

TEST(ImuPreintegrationFactor, Sizes) {
  Sampler s(7);
  const Problem pr(&s, -1.0, kNear);
  const auto factor = MakeFactor(pr.preintegrated);
  EXPECT_EQ(factor->num_residuals(), 18);
  EXPECT_EQ(factor->parameter_block_sizes(), (std::vector<int32_t>{19, 19}));
}

TEST(ImuPreintegrationFactor, JacobianIsCorrectAtRandomNearIdentityAndNearPiRotations) {
  Sampler s(8);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  // x_k's rotation at each angle, then x_k+1's (the other one near it).
  for (const bool vary_k : {true, false}) {
    for (double angle : angles) {
      SCOPED_TRACE(::testing::Message() << (vary_k ? "x_k " : "x_k+1 ") << angle);
      for (int trial = 0; trial < 3; ++trial) {
        const Problem pr(&s, vary_k ? angle : kNear, vary_k ? kNear : angle);
        const auto factor = MakeFactor(pr.preintegrated);
        const Blocks b(pr.x_k, pr.x_k1);
        EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, b.manifolds(), b.pointers()));
      }
    }
  }
  // Independent rotations: a large rotation residual. Log is not
  // differentiable at pi (the shortest rotation flips), so residuals within
  // 0.2 rad of pi are not probed.
  int checked = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Problem pr(&s, -1.0, -1.0);
    const auto factor = MakeFactor(pr.preintegrated);
    if (factor->Error(pr.x_k, pr.x_k1).head<3>().norm() > M_PI - 0.2) continue;
    const Blocks b(pr.x_k, pr.x_k1);
    EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, b.manifolds(), b.pointers()))
        << "trial " << trial;
    ++checked;
  }
  EXPECT_GE(checked, 8);
}

TEST(ImuPreintegrationFactor, FlippedColumnsAreRejected) {
  Sampler s(9);
  const Problem pr(&s, -1.0, kNear);
  const auto factor = MakeFactor(pr.preintegrated);
  const Blocks b(pr.x_k, pr.x_k1);
  ASSERT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, b.manifolds(), b.pointers()));
  using testing::FlippedJacobianColumns;
  // Ambient columns: q 0..3, p 4..6, v 7..9, b_g 10..12, b_a 13..15, g 16..18.
  const FlippedJacobianColumns flips[] = {
      {factor.get(), /*block=*/0, /*num_columns=*/4},  // rotation k
      {factor.get(), 0, 3, /*first_column=*/7},        // velocity k
      {factor.get(), 0, 3, 10},                        // gyro bias k
      {factor.get(), 0, 3, 16},                        // gravity k
      {factor.get(), 1, 4},                            // rotation k+1
      {factor.get(), 1, 3, 4},                         // position k+1
  };
  for (size_t i = 0; i < std::size(flips); ++i) {
    EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(flips[i], b.manifolds(), b.pointers()))
        << "flip " << i;
  }
}

TEST(ImuPreintegrationFactor, TangentJacobianMatchesNumericDifferentiation) {
  Sampler s(10);
  for (double angle : {-1.0, M_PI - 1e-3, 1e-9}) {
    SCOPED_TRACE(angle);
    const Problem pr(&s, angle, kNear);
    const auto factor = MakeFactor(pr.preintegrated);
    Matrix18 J_k, J_k1;
    factor->TangentJacobian(pr.x_k, pr.x_k1, &J_k, &J_k1);
    Eigen::Matrix<double, 18, 36> J;
    J << J_k, J_k1;
    const Eigen::MatrixXd numeric = testing::NumericJacobian(
        [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
          return factor->Residual(pr.x_k.BoxPlus(dx.head<18>()), pr.x_k1.BoxPlus(dx.tail<18>()));
        },
        36, 1e-7);
    const double scale = J.cwiseAbs().maxCoeff();
    EXPECT_TRUE(testing::MatricesNear(J / scale, numeric / scale, 1e-7, 1e-7));
  }
}

TEST(ImuPreintegrationFactor, WhitenedResidualIsTheMahalanobisDistance) {
  Sampler s(11);
  for (int trial = 0; trial < 5; ++trial) {
    const Problem pr(&s, -1.0, -1.0);
    const auto factor = MakeFactor(pr.preintegrated);
    const Vector18 e = factor->Error(pr.x_k, pr.x_k1);
    const Vector18 r = factor->Residual(pr.x_k, pr.x_k1);
    const double mahalanobis = e.dot(pr.preintegrated.covariance.ldlt().solve(e));
    EXPECT_NEAR(r.squaredNorm(), mahalanobis, 1e-8 * mahalanobis);
    const Matrix18& W = factor->sqrt_information();
    EXPECT_EQ(W.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0);
    EXPECT_LT((W * pr.preintegrated.covariance * W.transpose() - Matrix18::Identity()).norm(),
              1e-8);
    // The error is the header's definition.
    const Eigen::Matrix3d R_k = pr.x_k.R_G_b();
    const double T = pr.preintegrated.dt_s;
    const Eigen::Vector3d bg = pr.x_k.gyro_bias, ba = pr.x_k.accel_bias;
    Vector18 expected;
    expected << so3::Log(pr.preintegrated.CorrectedDeltaR(bg).transpose() * R_k.transpose() *
                         pr.x_k1.R_G_b()),
        R_k.transpose() * (pr.x_k1.p_b_in_G - pr.x_k.p_b_in_G - pr.x_k.v_b_in_G * T -
                           0.5 * T * T * pr.x_k.g_in_G) -
            pr.preintegrated.CorrectedDeltaP(bg, ba),
        R_k.transpose() * (pr.x_k1.v_b_in_G - pr.x_k.v_b_in_G - T * pr.x_k.g_in_G) -
            pr.preintegrated.CorrectedDeltaV(bg, ba),
        pr.x_k1.gyro_bias - bg, pr.x_k1.accel_bias - ba, pr.x_k1.g_in_G - pr.x_k.g_in_G;
    EXPECT_LT((e - expected).norm(), 1e-12 * (1.0 + expected.norm()));
  }
}

TEST(ImuPreintegrationFactor, ResidualsWithoutJacobianMatchFullEvaluation) {
  Sampler s(12);
  const Problem pr(&s, -1.0, -1.0);
  const auto factor = MakeFactor(pr.preintegrated);
  const Blocks b(pr.x_k, pr.x_k1);
  const std::vector<const double*> p = b.pointers();
  Vector18 r1, r2, r3;
  std::array<double, 18 * 19> j_k, j_k1;
  double* none[] = {nullptr, nullptr};
  double* only_k1[] = {nullptr, j_k1.data()};
  double* both[] = {j_k.data(), j_k1.data()};
  ASSERT_TRUE(factor->Evaluate(p.data(), r1.data(), nullptr));
  ASSERT_TRUE(factor->Evaluate(p.data(), r2.data(), none));
  ASSERT_TRUE(factor->Evaluate(p.data(), r3.data(), only_k1));
  EXPECT_EQ(r1, r2);
  EXPECT_EQ(r1, r3);
  ASSERT_TRUE(factor->Evaluate(p.data(), r3.data(), both));
  EXPECT_EQ(r1, r3);
}

// --- options and input errors ----------------------------------------------

TEST(ImuPreintegration, RejectsInvalidOptions) {
  std::unique_ptr<ImuPreintegration> pre;
  EXPECT_TRUE(ImuPreintegration::Create(DefaultOptions(), &pre).ok());
  ImuPreintegrationOptions options;
  options.process_noise.gyro_bias_cov_rad2_s4 = 0.0;  // valid for the filter, singular here
  Status status = ImuPreintegration::Create(options, &pre);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("process_noise.gyro_bias_cov_rad2_s4"), std::string::npos)
      << status.message();
  options = ImuPreintegrationOptions();
  options.gravity_stddev_floor_m_s2 = 0.0;
  status = ImuPreintegration::Create(options, &pre);
  EXPECT_NE(status.message().find("gravity_stddev_floor_m_s2"), std::string::npos)
      << status.message();
  options = ImuPreintegrationOptions();
  options.max_gap_s = -1.0;
  EXPECT_FALSE(ImuPreintegration::Create(options, &pre).ok());
}

TEST(ImuPreintegration, HandlesSamplesLikeThePropagator) {
  Sampler s(13);
  const Motion m(&s);
  std::unique_ptr<ImuPreintegration> pre;
  ASSERT_TRUE(ImuPreintegration::Create(DefaultOptions(), &pre).ok());
  // The last sample must not be after the start.
  EXPECT_EQ(pre->Reset(kImuPeriodNs - 1, m.Sample(kImuPeriodNs), 1.0, m.b_g, m.b_a).code(),
            Status::Code::kInvalidArgument);
  ImuSample bad = m.Sample(0);
  bad.angular_velocity_rad_s.x() = std::nan("");
  EXPECT_EQ(pre->Reset(0, bad, 1.0, m.b_g, m.b_a).code(), Status::Code::kInvalidArgument);
  ASSERT_TRUE(pre->Reset(0, m.Sample(0), 1.0, m.b_g, m.b_a).ok());
  // Duplicate of the start sample, a non-finite sample, a gap.
  EXPECT_TRUE(pre->AddImu(m.Sample(0)).ok());
  EXPECT_EQ(pre->num_skipped_duplicate(), 1);
  bad.stamp_ns = kImuPeriodNs;
  EXPECT_EQ(pre->AddImu(bad).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(pre->num_rejected_non_finite(), 1);
  EXPECT_EQ(pre->AddImu(m.Sample(30 * kImuPeriodNs)).code(), Status::Code::kOutOfRange);
  EXPECT_EQ(pre->num_gaps(), 1);
  EXPECT_EQ(pre->num_intervals(), 0);
  ASSERT_TRUE(pre->AddImu(m.Sample(kImuPeriodNs)).ok());
  ASSERT_TRUE(pre->AddImu(m.Sample(2 * kImuPeriodNs)).ok());
  // Out of order, back in time, next sample before the target.
  EXPECT_TRUE(pre->AddImu(m.Sample(kImuPeriodNs / 2)).ok());
  EXPECT_EQ(pre->num_skipped_out_of_order(), 1);
  EXPECT_EQ(pre->IntegrateTo(kImuPeriodNs).code(), Status::Code::kOutOfRange);
  const ImuSample early = m.Sample(2 * kImuPeriodNs + 100);
  EXPECT_EQ(pre->IntegrateTo(2 * kImuPeriodNs + 200, &early).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(pre->num_intervals(), 2);
  // A sample at a reached target becomes the input without a step.
  const ImuSample at_target = m.Sample(3 * kImuPeriodNs);
  ASSERT_TRUE(pre->IntegrateTo(3 * kImuPeriodNs, &at_target).ok());
  ASSERT_TRUE(pre->AddImu(at_target).ok());
  EXPECT_EQ(pre->num_intervals(), 3);
  EXPECT_EQ(pre->num_skipped_out_of_order(), 1);
  EXPECT_EQ(pre->preintegrated().dt_s, StampSeconds(3 * kImuPeriodNs));
}

TEST(ImuPreintegrationFactor, CreateRejectsUnusableMeasurements) {
  Sampler s(14);
  const Motion m(&s);
  std::unique_ptr<ImuPreintegrationFactor> factor;
  // One IMU interval: dp and dv are collinear, the covariance is singular.
  Window one;
  one.t_k_ns = 5 * kImuPeriodNs;
  one.t_k1_ns = 6 * kImuPeriodNs;
  const auto pre = Preintegrate(m, one, m.b_g, m.b_a);
  ASSERT_EQ(pre->num_intervals(), 1);
  EXPECT_EQ(ImuPreintegrationFactor::Create(pre->preintegrated(), &factor).code(),
            Status::Code::kInvalidArgument);
  // Two intervals are enough.
  Window two = one;
  two.t_k1_ns = 6 * kImuPeriodNs + 1'000'000;
  EXPECT_TRUE(
      ImuPreintegrationFactor::Create(Preintegrate(m, two, m.b_g, m.b_a)->preintegrated(), &factor)
          .ok());
  PreintegratedImu zero_length;
  EXPECT_EQ(ImuPreintegrationFactor::Create(zero_length, &factor).code(),
            Status::Code::kInvalidArgument);
  PreintegratedImu non_finite = Preintegrate(m, Window(), m.b_g, m.b_a)->preintegrated();
  non_finite.delta_v.x() = std::nan("");
  EXPECT_EQ(ImuPreintegrationFactor::Create(non_finite, &factor).code(),
            Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio
