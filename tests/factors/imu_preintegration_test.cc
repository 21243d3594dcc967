// ImuPreintegration against ImuPropagator on the same samples (fixture:
// imu_preintegration_test_fixture.h): the factor's residual is zero where the
// propagator lands (every end-point variant), consecutive intervals chain,
// the covariance equals the propagator's from P = 0, a one-state window
// reproduces the filter's covariance, the first-order bias correction
// against re-preintegration, and the bias Jacobians against numeric
// differentiation.
#include "imu_preintegration_test_fixture.h"

namespace swarmlio {
namespace {

using namespace imu_preintegration_test;  // NOLINT(build/namespaces): the fixture

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
      EXPECT_LT(run.x_k1.BoxMinus(m.State(ToSeconds(w.t_k1_ns))).norm(), 1e-3);
      // ... and the preintegration agrees with it to round-off.
      const auto pre = Preintegrate(m, w, run.x_k.gyro_bias, run.x_k.accel_bias);
      EXPECT_EQ(pre->preintegrated().dt_s, ToSeconds(w.t_k1_ns - w.t_k_ns));
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
  std::unique_ptr<lio::ImuPreintegration> pre;
  ASSERT_TRUE(lio::ImuPreintegration::Create(DefaultOptions(), &pre).ok());
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
    EgoState x_k = m.State(ToSeconds(w.t_k_ns));
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
    EgoState x_k = m.State(ToSeconds(w.t_k_ns));
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

}  // namespace
}  // namespace swarmlio
