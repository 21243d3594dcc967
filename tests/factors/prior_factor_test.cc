// PriorFactor: residual = L^T (x (-) x_hat) with L L^T = P^-1, and its
// analytic manifold Jacobian (ego + teammate blocks) against numeric
// differentiation in the tangent space, at random and near-pi rotations.
#include "factors/prior_factor.h"

#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <memory>
#include <random>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "test_utils/state_sampler.h"

namespace swarmlio {
namespace {

using Sampler = swarmlio::testing::StateSampler;

// Ceres parameter storage of a state plus the matching manifolds.
struct Blocks {
  explicit Blocks(const SwarmState& x) : teammates(x.layout().NumTeammates()) {
    x.ego.ToParameters(ego.data());
    manifolds.push_back(&ego_manifold);
    pointers.push_back(ego.data());
    const std::vector<int>& ids = x.layout().teammate_ids();
    for (size_t s = 0; s < ids.size(); ++s) {
      x.teammate(ids[s]).ToParameters(teammates[s].data());
      manifolds.push_back(&teammate_manifold);
      pointers.push_back(teammates[s].data());
    }
  }
  EgoStateManifold ego_manifold;
  GlobalExtrinsicManifold teammate_manifold;
  std::array<double, 19> ego;
  std::vector<std::array<double, 7>> teammates;
  std::vector<const ceres::Manifold*> manifolds;
  std::vector<const double*> pointers;
};

std::unique_ptr<PriorFactor> MakePrior(const SwarmState& x_hat, const Eigen::MatrixXd& P) {
  Eigen::MatrixXd U;
  EXPECT_TRUE(PriorFactor::CholeskyOfCovariance(P, &U));
  return std::make_unique<PriorFactor>(x_hat, U);
}

TEST(PriorFactor, BlockSizesFollowTheLayout) {
  Sampler s(1);
  const SwarmState x_hat = s.State(2, -1.0);
  const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
  EXPECT_EQ(prior->num_residuals(), 30);
  EXPECT_EQ(prior->parameter_block_sizes(), (std::vector<int32_t>{19, 7, 7}));
}

TEST(PriorFactor, ResidualIsWhitenedBoxMinus) {
  Sampler s(2);
  const SwarmState x_hat = s.State(2, -1.0);
  const Eigen::MatrixXd P = s.Covariance(x_hat.Dim(), 0.3, 0.05);
  const auto prior = MakePrior(x_hat, P);
  const SwarmState x = x_hat.BoxPlus(s.Gaussian(x_hat.Dim(), 0.5));
  const Eigen::VectorXd e = x.BoxMinus(x_hat);
  const Eigen::VectorXd r = prior->Residual(x);
  EXPECT_NEAR(r.squaredNorm(), e.dot(P.ldlt().solve(e)), 1e-9 * r.squaredNorm());

  Blocks blocks(x);
  Eigen::VectorXd r_ceres(x.Dim());
  ASSERT_TRUE(prior->Evaluate(blocks.pointers.data(), r_ceres.data(), nullptr));
  EXPECT_NEAR((r_ceres - r).norm(), 0.0, 1e-12);
  EXPECT_NEAR(prior->Residual(x_hat).norm(), 0.0, 1e-15);
}

TEST(PriorFactor, BoxMinusJacobianIsRightJacobianInverse) {
  Sampler s(3);
  const SwarmState x_hat = s.State(2, -1.0);
  const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
  const SwarmState x = x_hat.BoxPlus(s.Gaussian(x_hat.Dim(), 0.7));
  const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
    return x.BoxPlus(d).BoxMinus(x_hat);
  };
  EXPECT_TRUE(testing::MatricesNear(prior->BoxMinusJacobian(x),
                                    testing::NumericJacobian(f, x.Dim()), 1e-8));
  EXPECT_TRUE(prior->BoxMinusJacobian(x_hat).isIdentity(1e-15));
}

TEST(PriorFactor, TangentJacobianMatchesNumericBoxPlus) {
  Sampler s(8);
  for (int trial = 0; trial < 5; ++trial) {
    const SwarmState x_hat = s.State(2, -1.0);
    const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
    const SwarmState x = x_hat.BoxPlus(s.Gaussian(x_hat.Dim(), 0.5));
    const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return prior->Residual(x.BoxPlus(d));
    };
    EXPECT_TRUE(testing::MatricesNear(prior->TangentJacobian(x),
                                      testing::NumericJacobian(f, x.Dim()), 1e-7, 1e-7));
  }
}

// x = x_hat (+) dx with every rotation part of dx of norm `error_angle`.
SwarmState Perturb(Sampler* s, const SwarmState& x_hat, double error_angle, double scale) {
  Eigen::VectorXd dx = s->Gaussian(x_hat.Dim(), scale);
  dx.segment<3>(ErrorStateLayout::kRotation.offset) = s->Axis() * error_angle;
  for (int id : x_hat.layout().teammate_ids()) {
    dx.segment<3>(x_hat.layout().TeammateRotation(id).offset) = s->Axis() * error_angle;
  }
  return x_hat.BoxPlus(dx);
}

struct Regime {
  const char* name;
  double state_angle;  // rotation of x_hat's blocks (< 0: uniformly random)
  double error_angle;  // |rotation part| of x (-) x_hat [rad]
  double error_scale;  // std of the Euclidean parts of x (-) x_hat
};

// Ceres's GradientChecker compares entries by relative error only and uses
// Ridders differences that start with 1e-2 relative ambient steps; its
// tableau stops early at ~1e-5 absolute accuracy on this residual, so tiny
// entries of U^-1 J fail it at x == x_hat (exact zeros vs 1e-17), at
// |x (-) x_hat| ~ 1e-3 and beyond ~2.5 rad, although ambient central
// differences converge to the analytic Jacobian as O(h^2). Those points are
// covered by JacobianAtXHatAndNearPiDifference (central differences through
// BoxPlus, 1e-8).
TEST(PriorFactor, JacobiansAreCorrectWithTeammates) {
  const Regime regimes[] = {{"random", -1.0, 0.7, 0.5},
                            {"near_pi_states", M_PI - 1e-7, 0.7, 0.5},
                            {"near_pi_states_2", M_PI - 1e-3, 1.5, 0.5},
                            {"large_euclidean_error", -1.0, 1.0, 5.0}};
  Sampler s(4);
  for (const Regime& regime : regimes) {
    SCOPED_TRACE(regime.name);
    for (int trial = 0; trial < 12; ++trial) {
      const int num_teammates = trial % 3;
      const SwarmState x_hat = s.State(num_teammates, regime.state_angle);
      const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
      const SwarmState x = Perturb(&s, x_hat, regime.error_angle, regime.error_scale);
      Blocks blocks(x);
      EXPECT_TRUE(
          testing::CostFunctionJacobiansAreCorrect(*prior, blocks.manifolds, blocks.pointers));
    }
  }
}

// Ceres ambient Jacobian times PlusJacobian == tangent Jacobian, compared
// with central differences through SwarmState::BoxPlus, at x_hat and up to
// 0.04 rad from the branch cut of Log.
TEST(PriorFactor, JacobianAtXHatAndNearPiDifference) {
  Sampler s(5);
  for (double error_angle : {0.0, 1e-3, 0.7, 2.5, 2.8, 3.0, M_PI - 0.04}) {
    SCOPED_TRACE(error_angle);
    const SwarmState x_hat = s.State(2, -1.0);
    const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
    const SwarmState x = Perturb(&s, x_hat, error_angle, error_angle > 0 ? 0.3 : 0.0);
    Blocks blocks(x);
    const int n = x.Dim();
    Eigen::Matrix<double, Eigen::Dynamic, 19, Eigen::RowMajor> j0(n, 19);
    Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> j1(n, 7), j2(n, 7);
    Eigen::VectorXd r(n);
    double* jacobians[] = {j0.data(), j1.data(), j2.data()};
    ASSERT_TRUE(prior->Evaluate(blocks.pointers.data(), r.data(), jacobians));
    Eigen::Matrix<double, 19, 18, Eigen::RowMajor> plus_ego;
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_1, plus_2;
    blocks.ego_manifold.PlusJacobian(blocks.pointers[0], plus_ego.data());
    blocks.teammate_manifold.PlusJacobian(blocks.pointers[1], plus_1.data());
    blocks.teammate_manifold.PlusJacobian(blocks.pointers[2], plus_2.data());
    Eigen::MatrixXd J_tangent(n, n);
    J_tangent << j0 * plus_ego, j1 * plus_1, j2 * plus_2;
    const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return prior->Residual(x.BoxPlus(d));
    };
    EXPECT_TRUE(testing::MatricesNear(J_tangent, testing::NumericJacobian(f, n), 1e-8, 1e-8));
    EXPECT_TRUE(testing::MatricesNear(J_tangent, prior->TangentJacobian(x), 1e-12, 1e-12));
  }
}

TEST(PriorFactor, FlippedSignIsRejected) {
  Sampler s(6);
  const SwarmState x_hat = s.State(2, -1.0);
  const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
  const SwarmState x = x_hat.BoxPlus(s.Gaussian(x_hat.Dim(), 0.5));
  Blocks blocks(x);
  const testing::FlippedJacobianColumns flipped(prior.get(), /*block=*/0, /*num_columns=*/4);
  EXPECT_FALSE(
      testing::CostFunctionJacobiansAreCorrect(flipped, blocks.manifolds, blocks.pointers));
}

TEST(PriorFactor, HonoursNullJacobianPerBlock) {
  Sampler s(7);
  const SwarmState x_hat = s.State(2, -1.0);
  const auto prior = MakePrior(x_hat, s.Covariance(x_hat.Dim(), 0.3, 0.05));
  const SwarmState x = x_hat.BoxPlus(s.Gaussian(x_hat.Dim(), 0.5));
  Blocks blocks(x);
  const int n = x.Dim();
  std::vector<double> r(n), j0(n * 19), j1(n * 7), j2(n * 7), k2(n * 7, 0.0);
  double* all[] = {j0.data(), j1.data(), j2.data()};
  ASSERT_TRUE(prior->Evaluate(blocks.pointers.data(), r.data(), all));
  double* some[] = {nullptr, nullptr, k2.data()};
  ASSERT_TRUE(prior->Evaluate(blocks.pointers.data(), r.data(), some));
  EXPECT_EQ(j2, k2);
}

TEST(PriorFactor, CholeskyRejectsNonPositiveDefinite) {
  Eigen::MatrixXd U;
  EXPECT_FALSE(PriorFactor::CholeskyOfCovariance(-Eigen::MatrixXd::Identity(18, 18), &U));
  EXPECT_FALSE(PriorFactor::CholeskyOfCovariance(Eigen::MatrixXd::Zero(18, 18), &U));
  EXPECT_FALSE(PriorFactor::CholeskyOfCovariance(Eigen::MatrixXd::Identity(18, 17), &U));
  Eigen::MatrixXd P = Eigen::MatrixXd::Identity(18, 18);
  P(3, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(PriorFactor::CholeskyOfCovariance(P, &U));
  ASSERT_TRUE(PriorFactor::CholeskyOfCovariance(4.0 * Eigen::MatrixXd::Identity(18, 18), &U));
  EXPECT_TRUE(U.isApprox(2.0 * Eigen::MatrixXd::Identity(18, 18)));
}

}  // namespace
}  // namespace swarmlio
