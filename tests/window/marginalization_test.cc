// Marginalizer and MarginalizationPriorFactor (docs/window.md, "Marginalization
// prior"). A window of three ego states x0, x1, x2 and one global extrinsic T,
// linked by the project's factors (prior, IMU preintegration, active and
// passive observations, pose information), is linearized by Ceres itself
// (ceres::Problem::Evaluate, tangent-space Jacobians with the losses applied),
// independently of the Marginalizer. Checks:
//   (a) (H*)^-1 equals the kept blocks' block of the dense inverse of the full
//       information matrix, and b* the dense elimination, to 1e-9 relative;
//   (b) one Gauss-Newton step with the prior in place of the marginalized
//       block(s) equals the full problem's step, to 1e-9 relative;
//   (c) the prior factor's Jacobians pass the GradientChecker at x0 and away
//       from it, and flipped signs are rejected;
//   (d) at x = x0 the prior's cost is 1/2 b*^T H*^+ b*;
// plus a rank-deficient H_mm and H*, a quaternion sign flip, and the
// Status errors.
#include "marginalization_test_util.h"

namespace swarmlio::window::marginalization_test {
namespace {

TEST(Marginalizer, PriorEqualsTheDenseGaussianMarginal) {
  unsigned seed = 10;
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    Window w(++seed, c.with_losses);
    const Split split = SplitOf(&w, c);
    const std::vector<Term> terms = w.Touching(split.marginalized);
    MarginalizationPrior prior;
    const Status status = Marginalize(terms, split.marginalized, split.kept, &prior);
    ASSERT_TRUE(status.ok()) << status.message();

    std::vector<double*> order = split.kept;
    order.insert(order.end(), split.marginalized.begin(), split.marginalized.end());
    const LinearSystem sys = Linearize(terms, order);
    const int n = prior.TangentDim();
    const int m = static_cast<int>(sys.H.rows()) - n;
    EXPECT_EQ(prior.marginalized_dim, m);
    EXPECT_EQ(prior.marginalized_rank, m);
    ASSERT_EQ(prior.information.rows(), n);

    const Eigen::MatrixXd R =
        (c.marginalize_extrinsic ? 1.0 : 0.0) * Eigen::MatrixXd::Identity(n, n);
    Eigen::MatrixXd H = sys.H;
    H.topLeftCorner(n, n) += R;
    const Eigen::MatrixXd Sigma = H.ldlt().solve(Eigen::MatrixXd::Identity(n + m, n + m));
    const Eigen::MatrixXd Sigma_kk = Sigma.topLeftCorner(n, n);
    const Eigen::MatrixXd prior_covariance =
        (prior.information + R).ldlt().solve(Eigen::MatrixXd::Identity(n, n));
    const double covariance_error = RelativeError(prior_covariance, Sigma_kk);
    EXPECT_LT(covariance_error, kTolerance);

    const Eigen::VectorXd dx = -H.ldlt().solve(sys.g);
    const Eigen::VectorXd b_dense = -Sigma_kk.ldlt().solve(dx.head(n));
    const double gradient_error = RelativeError(prior.gradient, b_dense);
    EXPECT_LT(gradient_error, kTolerance);
    EXPECT_GT(b_dense.norm(), 1.0);  // not a trivial linearization point
    RecordProperty(std::string("covariance_error ") + c.name, Scientific(covariance_error));
    RecordProperty(std::string("gradient_error ") + c.name, Scientific(gradient_error));

    // The losses are applied (Ceres's correction): without them H* differs.
    if (c.with_losses) {
      std::vector<Term> without_losses = terms;
      for (Term& t : without_losses) t.loss = nullptr;
      MarginalizationPrior plain;
      ASSERT_TRUE(Marginalize(without_losses, split.marginalized, split.kept, &plain).ok());
      EXPECT_GT(RelativeError(plain.information, prior.information), 1e-3);
    }

    // The linearization points are copies of the kept blocks' values.
    for (size_t i = 0; i < split.kept.size(); ++i) {
      EXPECT_EQ(prior.parameter_blocks[i], split.kept[i]);
      EXPECT_EQ(prior.manifolds[i], w.ManifoldOf(split.kept[i]));
      EXPECT_TRUE(prior.linearization_points[i] ==
                  Eigen::Map<const Eigen::VectorXd>(split.kept[i], prior.ambient_sizes[i]));
    }
  }
}

// (b) One Gauss-Newton step from the linearization point with the prior in
// place of the marginalized blocks equals the full problem's step.
TEST(Marginalizer, OneGaussNewtonStepWithThePriorEqualsTheFullStep) {
  unsigned seed = 20;
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    Window w(++seed, c.with_losses);
    const Split split = SplitOf(&w, c);
    MarginalizationPrior prior;
    const Status status =
        Marginalize(w.Touching(split.marginalized), split.marginalized, split.kept, &prior);
    ASSERT_TRUE(status.ok()) << status.message();
    const std::unique_ptr<MarginalizationPriorFactor> factor = PriorFactorOf(prior);
    ASSERT_NE(factor, nullptr);

    // Full problem: all blocks, the remaining ones first.
    std::vector<double*> remaining;
    for (double* b : w.AllBlocks()) {
      if (std::find(split.marginalized.begin(), split.marginalized.end(), b) ==
          split.marginalized.end()) {
        remaining.push_back(b);
      }
    }
    std::vector<double*> full_order = remaining;
    full_order.insert(full_order.end(), split.marginalized.begin(), split.marginalized.end());
    const LinearSystem full = Linearize(w.terms(), full_order);
    const Eigen::VectorXd dx_full = -full.H.ldlt().solve(full.g);

    // Reduced problem: the other residuals plus the prior.
    std::vector<Term> reduced_terms = w.NotTouching(split.marginalized);
    Term prior_term;
    prior_term.cost = factor.get();
    prior_term.blocks = prior.parameter_blocks;
    prior_term.manifolds = prior.manifolds;
    reduced_terms.push_back(prior_term);
    const LinearSystem reduced = Linearize(reduced_terms, remaining);
    const Eigen::VectorXd dx_reduced = -reduced.H.ldlt().solve(reduced.g);

    ASSERT_EQ(dx_reduced.size(), 18 + 18 + (c.marginalize_extrinsic ? 0 : 6));
    const double step_error = RelativeError(dx_reduced, dx_full.head(dx_reduced.size()));
    EXPECT_LT(step_error, kTolerance);
    EXPECT_GT(dx_reduced.norm(), 1e-3);
    RecordProperty(std::string("step_error ") + c.name, Scientific(step_error));
  }
}

// (c) The prior factor's Jacobians (J* C(x) lifted with MinusJacobian) pass
// the GradientChecker at x0 and away from x0; flipped signs are rejected.
TEST(MarginalizationPriorFactor, JacobiansPassTheCheckerAndFlippedSignsFail) {
  Window w(30, false);
  const Split split = SplitOf(&w, kCases[0]);  // kept: x1 (ego), T (extrinsic)
  MarginalizationPrior prior;
  ASSERT_TRUE(
      Marginalize(w.Touching(split.marginalized), split.marginalized, split.kept, &prior).ok());
  const std::unique_ptr<MarginalizationPriorFactor> factor = PriorFactorOf(prior);
  ASSERT_NE(factor, nullptr);
  EXPECT_EQ(factor->num_residuals(), 18 + 6);
  EXPECT_EQ(factor->parameter_block_sizes(), (std::vector<int32_t>{19, 7}));
  EXPECT_EQ(factor->rank(), 24);

  Sampler s(31);
  const EgoState ego0 = EgoState::FromParameters(prior.linearization_points[0].data());
  const GlobalExtrinsic ext0 =
      GlobalExtrinsic::FromParameters(prior.linearization_points[1].data());
  for (double scale : {0.0, 0.01, 0.3, 1.0}) {
    SCOPED_TRACE(::testing::Message() << "perturbation scale " << scale);
    std::array<double, EgoState::kAmbientSize> x_ego;
    std::array<double, GlobalExtrinsic::kAmbientSize> x_ext;
    s.Perturb(ego0, scale).ToParameters(x_ego.data());
    s.Perturb(ext0, scale).ToParameters(x_ext.data());
    const std::vector<const double*> parameters = {x_ego.data(), x_ext.data()};
    EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, prior.manifolds, parameters));
    using testing::FlippedJacobianColumns;
    const FlippedJacobianColumns ego_rotation(factor.get(), 0, 4);
    const FlippedJacobianColumns ego_velocity(factor.get(), 0, 3, 7);
    const FlippedJacobianColumns ext_rotation(factor.get(), 1, 4);
    const FlippedJacobianColumns ext_position(factor.get(), 1, 3, 4);
    const std::vector<const ceres::CostFunction*> flipped_factors = {&ego_rotation, &ego_velocity,
                                                                     &ext_rotation, &ext_position};
    for (const ceres::CostFunction* flipped : flipped_factors) {
      EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(*flipped, prior.manifolds, parameters));
    }
  }
}

// The residual is the fixed linear model J* dx + r0 in dx = x (-) x0 (FEJ),
// with dx from the state's own boxminus; a quaternion stored with the other
// sign (the same rotation) gives the same residual.
TEST(MarginalizationPriorFactor, ResidualIsTheFixedLinearModelInTheBoxminus) {
  Window w(40, true);
  const Split split = SplitOf(&w, kCases[0]);
  MarginalizationPrior prior;
  ASSERT_TRUE(
      Marginalize(w.Touching(split.marginalized), split.marginalized, split.kept, &prior).ok());
  const std::unique_ptr<MarginalizationPriorFactor> factor = PriorFactorOf(prior);
  ASSERT_NE(factor, nullptr);
  const EgoState ego0 = EgoState::FromParameters(prior.linearization_points[0].data());
  const GlobalExtrinsic ext0 =
      GlobalExtrinsic::FromParameters(prior.linearization_points[1].data());
  Sampler s(41);
  for (int trial = 0; trial < 5; ++trial) {
    const EgoState ego = s.Perturb(ego0, 0.5);
    const GlobalExtrinsic ext = s.Perturb(ext0, 0.5);
    Eigen::VectorXd dx(24);
    dx << ego.BoxMinus(ego0), ext.BoxMinus(ext0);
    const Eigen::VectorXd expected =
        factor->sqrt_information() * dx + factor->linearization_residual();
    std::array<double, EgoState::kAmbientSize> x_ego;
    std::array<double, GlobalExtrinsic::kAmbientSize> x_ext;
    ego.ToParameters(x_ego.data());
    ext.ToParameters(x_ext.data());
    const double* parameters[] = {x_ego.data(), x_ext.data()};
    Eigen::VectorXd r(24);
    ASSERT_TRUE(factor->Evaluate(parameters, r.data(), nullptr));
    EXPECT_LT((r - expected).norm(), 1e-12 * expected.norm());

    for (int i = 0; i < 4; ++i) {
      x_ego[i] = -x_ego[i];
      x_ext[i] = -x_ext[i];
    }
    Eigen::VectorXd r_flipped(24);
    ASSERT_TRUE(factor->Evaluate(parameters, r_flipped.data(), nullptr));
    EXPECT_LT((r_flipped - expected).norm(), 1e-12 * expected.norm());
    EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(
        *factor, prior.manifolds, std::vector<const double*>{x_ego.data(), x_ext.data()}));
  }
}

// (d) At x = x0: r = r0, J*^T J* = H*, J*^T r0 = b*, and the cost
// 1/2 |r0|^2 = 1/2 b*^T H*^+ b*.
TEST(MarginalizationPriorFactor, CostAtTheLinearizationPointIsTheEliminatedConstant) {
  unsigned seed = 50;
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    Window w(++seed, c.with_losses);
    const Split split = SplitOf(&w, c);
    MarginalizationPrior prior;
    ASSERT_TRUE(
        Marginalize(w.Touching(split.marginalized), split.marginalized, split.kept, &prior).ok());
    const std::unique_ptr<MarginalizationPriorFactor> factor = PriorFactorOf(prior);
    ASSERT_NE(factor, nullptr);
    const int n = prior.TangentDim();
    std::vector<const double*> x0;
    for (const Eigen::VectorXd& x : prior.linearization_points) x0.push_back(x.data());
    Eigen::VectorXd r(n);
    ASSERT_TRUE(factor->Evaluate(x0.data(), r.data(), nullptr));
    EXPECT_LT((r - factor->linearization_residual()).norm(), 1e-12 * r.norm());

    const Eigen::MatrixXd& J = factor->sqrt_information();
    EXPECT_LT(RelativeError(J.transpose() * J, prior.information), 1e-12);
    EXPECT_LT(RelativeError(J.transpose() * factor->linearization_residual(), prior.gradient),
              1e-12);
    const Eigen::MatrixXd H_pinv =
        prior.information.completeOrthogonalDecomposition().pseudoInverse();
    const double expected_cost = 0.5 * prior.gradient.dot(H_pinv * prior.gradient);
    const double cost = 0.5 * r.squaredNorm();
    EXPECT_NEAR(cost, expected_cost, 1e-9 * expected_cost);
    EXPECT_GT(cost, 0.0);
  }
}

// A linear residual sum_i A_i x_i + c over Euclidean blocks.

}  // namespace
}  // namespace swarmlio::window::marginalization_test
