// Ceres manifold invariants (Plus/Minus consistency and both Jacobians checked
// numerically) for every parameter-block manifold, at random points, near the
// identity and near a rotation of pi.
#include <ceres/manifold_test_utils.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "factors/so3_manifold.h"
#include "swarmlio/math/so3.h"

// Ceres's invariant macro uses names from namespace ceres unqualified.
namespace ceres {
void ExpectManifoldInvariants(const Manifold& manifold, const Vector& x, const Vector& delta,
                              const Vector& y, double tolerance) {
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, tolerance);
}
}  // namespace ceres

namespace swarmlio {
namespace {

constexpr int kNumTrials = 200;
constexpr double kTolerance = 1e-9;

class Sampler {
 public:
  explicit Sampler(unsigned seed) : rng_(seed) {}
  Eigen::Vector3d Axis() { return Eigen::Vector3d(n_(rng_), n_(rng_), n_(rng_)).normalized(); }
  // Unit quaternion (x y z w) of a rotation by `angle` (random when < 0).
  Eigen::Vector4d Quaternion(double angle = -1.0) {
    if (angle < 0) {
      Eigen::Vector4d q(n_(rng_), n_(rng_), n_(rng_), n_(rng_));
      return q.normalized();
    }
    return so3::ExpQuaternion(Axis() * angle).coeffs();
  }
  Eigen::VectorXd Gaussian(int n, double scale) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v[i] = scale * n_(rng_);
    return v;
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> n_;
};

// Rotation angles of the base point and of the tangent step: random, tiny
// (1e-8 from identity) and close to pi.
struct Regime {
  const char* name;
  double x_angle;      // < 0: random rotation
  double delta_angle;  // norm of the rotation part of delta
};
const Regime kRegimes[] = {
    {"random", -1.0, 1.0},
    {"near_identity", 1e-8, 1e-8},
    {"near_pi", M_PI - 1e-6, M_PI - 1e-3},
    {"identity_exact", 0.0, 0.0},
};

TEST(SO3Manifold, SizesAreQuaternionAndRotationVector) {
  SO3Manifold m;
  EXPECT_EQ(m.AmbientSize(), 4);
  EXPECT_EQ(m.TangentSize(), 3);
}

TEST(SO3Manifold, InvariantsHold) {
  SO3Manifold manifold;
  Sampler s(11);
  for (const Regime& regime : kRegimes) {
    SCOPED_TRACE(regime.name);
    for (int trial = 0; trial < kNumTrials; ++trial) {
      const ceres::Vector x = s.Quaternion(regime.x_angle);
      const ceres::Vector delta = s.Axis() * regime.delta_angle;
      const ceres::Vector y = s.Quaternion();
      ceres::ExpectManifoldInvariants(manifold, x, delta, y, kTolerance);
    }
  }
}

TEST(SO3Manifold, PlusIsRightPerturbation) {
  SO3Manifold manifold;
  Sampler s(12);
  const Eigen::Vector4d x = s.Quaternion();
  const Eigen::Vector3d dr(0.1, -0.3, 0.2);
  Eigen::Vector4d y;
  ASSERT_TRUE(manifold.Plus(x.data(), dr.data(), y.data()));
  const Eigen::Matrix3d R_x = Eigen::Quaterniond(x[3], x[0], x[1], x[2]).toRotationMatrix();
  const Eigen::Matrix3d R_y = Eigen::Quaterniond(y[3], y[0], y[1], y[2]).toRotationMatrix();
  EXPECT_NEAR((R_y - R_x * so3::Exp(dr)).norm(), 0.0, 1e-14);
}

TEST(SO3Manifold, LiftedTangentJacobianReturnsThroughPlusJacobian) {
  SO3Manifold manifold;
  Sampler s(13);
  const Eigen::Vector4d x = s.Quaternion();
  const Eigen::Matrix<double, 2, 3> J_tangent = Eigen::Matrix<double, 2, 3>::Random();
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus_jacobian;
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus_jacobian.data()));
  const Eigen::Matrix<double, 2, 4> J_ambient =
      SO3Manifold::LiftTangentJacobian<2>(J_tangent, x.data());
  EXPECT_NEAR((J_ambient * plus_jacobian - J_tangent).norm(), 0.0, 1e-15);
}

TEST(EgoStateManifold, InvariantsHoldAndLayoutMatches) {
  EgoStateManifold manifold;
  EXPECT_EQ(manifold.AmbientSize(), EgoState::kAmbientSize);
  EXPECT_EQ(manifold.TangentSize(), ErrorStateLayout::kEgoDim);
  Sampler s(21);
  for (const Regime& regime : kRegimes) {
    SCOPED_TRACE(regime.name);
    for (int trial = 0; trial < kNumTrials / 4; ++trial) {
      ceres::Vector x(19), y(19), delta(18);
      x << s.Quaternion(regime.x_angle), s.Gaussian(15, 3.0);
      y << s.Quaternion(), s.Gaussian(15, 3.0);
      delta << s.Axis() * regime.delta_angle, s.Gaussian(15, 1.0);
      ceres::ExpectManifoldInvariants(manifold, x, delta, y, kTolerance);
    }
  }
}

TEST(EgoStateManifold, PlusAgreesWithEgoStateBoxPlus) {
  EgoStateManifold manifold;
  Sampler s(22);
  EgoState state;
  state.q_G_b = Eigen::Quaterniond(Eigen::Vector4d(s.Quaternion()));
  state.p_b_in_G = s.Gaussian(3, 2.0);
  state.v_b_in_G = s.Gaussian(3, 1.0);
  const Eigen::Matrix<double, 18, 1> dx = s.Gaussian(18, 0.5);
  double x[19], x_plus[19];
  state.ToParameters(x);
  ASSERT_TRUE(manifold.Plus(x, dx.data(), x_plus));
  EXPECT_NEAR(EgoState::FromParameters(x_plus).BoxMinus(state.BoxPlus(dx)).norm(), 0.0, 1e-14);
}

TEST(GlobalExtrinsicManifold, InvariantsHoldAndAgreeWithBoxPlus) {
  GlobalExtrinsicManifold manifold;
  EXPECT_EQ(manifold.AmbientSize(), GlobalExtrinsic::kAmbientSize);
  EXPECT_EQ(manifold.TangentSize(), ErrorStateLayout::kTeammateDim);
  Sampler s(31);
  for (const Regime& regime : kRegimes) {
    SCOPED_TRACE(regime.name);
    for (int trial = 0; trial < kNumTrials / 4; ++trial) {
      ceres::Vector x(7), y(7), delta(6);
      x << s.Quaternion(regime.x_angle), s.Gaussian(3, 10.0);
      y << s.Quaternion(), s.Gaussian(3, 10.0);
      delta << s.Axis() * regime.delta_angle, s.Gaussian(3, 1.0);
      ceres::ExpectManifoldInvariants(manifold, x, delta, y, kTolerance);

      const GlobalExtrinsic e = GlobalExtrinsic::FromParameters(x.data());
      ceres::Vector x_plus(7);
      ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), x_plus.data()));
      EXPECT_NEAR(GlobalExtrinsic::FromParameters(x_plus.data())
                      .BoxMinus(e.BoxPlus(delta.head<6>()))
                      .norm(),
                  0.0, 1e-12);
    }
  }
}

}  // namespace
}  // namespace swarmlio
