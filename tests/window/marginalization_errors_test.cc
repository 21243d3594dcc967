// Marginalizer and MarginalizationPriorFactor on degenerate and invalid
// input: a rank-deficient H_mm and H* (pseudo-inverse), the Status errors for
// invalid blocks and non-finite linearizations (docs/window.md).
#include "marginalization_test_util.h"

namespace swarmlio::window::marginalization_test {
namespace {

class LinearCost final : public ceres::CostFunction {
 public:
  LinearCost(std::vector<Eigen::MatrixXd> A, Eigen::VectorXd c)
      : A_(std::move(A)), c_(std::move(c)) {
    set_num_residuals(static_cast<int>(c_.size()));
    for (const Eigen::MatrixXd& a : A_) {
      mutable_parameter_block_sizes()->push_back(static_cast<int32_t>(a.cols()));
    }
  }
  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    Eigen::Map<Eigen::VectorXd> r(residuals, c_.size());
    r = c_;
    for (size_t i = 0; i < A_.size(); ++i) {
      r += A_[i] * Eigen::Map<const Eigen::VectorXd>(parameters[i], A_[i].cols());
      if (jacobians != nullptr && jacobians[i] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobians[i], A_[i].rows(), A_[i].cols()) = A_[i];
      }
    }
    return true;
  }

 private:
  std::vector<Eigen::MatrixXd> A_;
  Eigen::VectorXd c_;
};

// A marginalized Euclidean block with a direction no residual constrains:
// H_mm is singular, the pseudo-inverse drops that direction (rank 2 of 3),
// and H*, b* equal the elimination of the constrained part alone. The kept
// block k (3) is observed only along two directions, so H* has rank 2 too and
// the factor keeps 2 rows.
TEST(Marginalizer, SingularMarginalizedAndKeptDirectionsArePseudoInverted) {
  Sampler s(60);
  Eigen::VectorXd k = s.Gaussian(3, 1.0), m = s.Gaussian(3, 1.0);
  ceres::EuclideanManifold<ceres::DYNAMIC> euclidean3(3);
  // Residual: 4 rows over (k, m); m's third coordinate and k's third are unused.
  Eigen::MatrixXd A_k = Eigen::MatrixXd::Zero(4, 3), A_m = Eigen::MatrixXd::Zero(4, 3);
  A_k.leftCols(2) = s.Gaussian(8, 1.0).reshaped(4, 2);
  A_m.leftCols(2) = s.Gaussian(8, 1.0).reshaped(4, 2);
  LinearCost cost({A_k, A_m}, s.Gaussian(4, 1.0));
  Term term;
  term.cost = &cost;
  term.blocks = {k.data(), m.data()};
  term.manifolds = {nullptr, &euclidean3};
  MarginalizationPrior prior;
  const Status status = Marginalize({term}, {m.data()}, {k.data()}, &prior);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(prior.marginalized_dim, 3);
  EXPECT_EQ(prior.marginalized_rank, 2);

  // Elimination of m's constrained part alone: [A_k | A_m2], A_m2 = m's first two columns.
  Eigen::MatrixXd A(4, 5);
  A << A_k, A_m.leftCols(2);
  Eigen::VectorXd r(4);
  const double* values[] = {k.data(), m.data()};
  ASSERT_TRUE(cost.Evaluate(values, r.data(), nullptr));
  const Eigen::MatrixXd H = A.transpose() * A;
  const Eigen::VectorXd b = A.transpose() * r;
  const Eigen::MatrixXd H_mm_inv = H.bottomRightCorner(2, 2).inverse();
  const Eigen::MatrixXd H_star =
      H.topLeftCorner(3, 3) - H.topRightCorner(3, 2) * H_mm_inv * H.bottomLeftCorner(2, 3);
  const Eigen::VectorXd b_star = b.head(3) - H.topRightCorner(3, 2) * H_mm_inv * b.tail(2);
  EXPECT_LT(RelativeError(prior.information, H_star), 1e-12);
  EXPECT_LT(RelativeError(prior.gradient, b_star), 1e-12);

  // H* has rank 2: the factor keeps two rows, still J*^T J* = H*, J*^T r0 = b*.
  const std::unique_ptr<MarginalizationPriorFactor> factor = PriorFactorOf(prior);
  ASSERT_NE(factor, nullptr);
  EXPECT_EQ(factor->num_residuals(), 3);
  EXPECT_EQ(factor->rank(), 2);
  const Eigen::MatrixXd& J = factor->sqrt_information();
  EXPECT_LT(RelativeError(J.transpose() * J, H_star), 1e-12);
  EXPECT_LT(RelativeError(J.transpose() * factor->linearization_residual(), b_star), 1e-12);
  const Eigen::MatrixXd H_pinv = H_star.completeOrthogonalDecomposition().pseudoInverse();
  const double expected_cost = 0.5 * b_star.dot(H_pinv * b_star);
  EXPECT_NEAR(0.5 * factor->linearization_residual().squaredNorm(), expected_cost,
              1e-10 * expected_cost);
  const std::vector<const ceres::Manifold*> manifolds = {nullptr};
  EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(*factor, manifolds,
                                                       std::vector<const double*>{k.data()}));
}

TEST(Marginalizer, RejectsInvalidInput) {
  Window w(70, false);
  const std::vector<double*> marginalized = {w.ego(0)};
  const std::vector<double*> kept = {w.ego(1), w.extrinsic()};
  const std::vector<Term> terms = w.Touching(marginalized);
  MarginalizationPrior prior;
  const auto code = [](const Status& status) { return status.code(); };
  using Code = Status::Code;

  MarginalizationOptions bad_options;
  bad_options.min_relative_eigenvalue = -1.0;
  std::unique_ptr<Marginalizer> marginalizer;
  EXPECT_EQ(code(Marginalizer::Create(bad_options, &marginalizer)), Code::kInvalidArgument);
  ASSERT_TRUE(Marginalizer::Create(MarginalizationOptions(), &marginalizer).ok());

  // AddResidualBlock: sizes, nulls, repeats.
  MarginalizationResidualBlock block;
  EXPECT_EQ(code(marginalizer->AddResidualBlock(block)), Code::kInvalidArgument);  // null cost
  block.cost_function = terms[1].cost;                                             // IMU (x0, x1)
  block.parameter_blocks = {w.ego(0)};
  block.manifolds = {w.ManifoldOf(w.ego(0))};
  EXPECT_EQ(code(marginalizer->AddResidualBlock(block)), Code::kInvalidArgument);  // 1 of 2 blocks
  block.parameter_blocks = {w.ego(0), w.ego(0)};
  block.manifolds = {w.ManifoldOf(w.ego(0)), w.ManifoldOf(w.ego(0))};
  EXPECT_EQ(code(marginalizer->AddResidualBlock(block)), Code::kInvalidArgument);  // repeated
  block.parameter_blocks = {w.ego(0), w.ego(1)};
  block.manifolds = {w.ManifoldOf(w.ego(0)), w.ManifoldOf(w.extrinsic())};
  EXPECT_EQ(code(marginalizer->AddResidualBlock(block)), Code::kInvalidArgument);  // 7 != 19
  EXPECT_EQ(code(marginalizer->Marginalize(marginalized, kept, &prior)), Code::kInvalidArgument);

  for (const Term& t : terms) {
    block.cost_function = t.cost;
    block.loss_function = t.loss;
    block.parameter_blocks = t.blocks;
    block.manifolds = t.manifolds;
    ASSERT_TRUE(marginalizer->AddResidualBlock(block).ok());
  }
  EXPECT_EQ(marginalizer->num_residual_blocks(), static_cast<int>(terms.size()));
  // Lists: empty, overlapping, incomplete, a block in no residual.
  EXPECT_EQ(code(marginalizer->Marginalize({}, kept, &prior)), Code::kInvalidArgument);
  EXPECT_EQ(code(marginalizer->Marginalize(marginalized, {}, &prior)), Code::kInvalidArgument);
  EXPECT_EQ(code(marginalizer->Marginalize(marginalized, {w.ego(1), w.ego(0)}, &prior)),
            Code::kInvalidArgument);
  EXPECT_EQ(code(marginalizer->Marginalize(marginalized, {w.ego(1)}, &prior)),
            Code::kInvalidArgument);
  EXPECT_EQ(
      code(marginalizer->Marginalize(marginalized, {w.ego(1), w.extrinsic(), w.ego(2)}, &prior)),
      Code::kInvalidArgument);
  EXPECT_TRUE(prior.parameter_blocks.empty());  // untouched on error
  ASSERT_TRUE(marginalizer->Marginalize(marginalized, kept, &prior).ok());

  // A residual that touches no marginalized block would be counted twice.
  const std::vector<Term> others = w.NotTouching(marginalized);
  block.cost_function = others[0].cost;
  block.loss_function = others[0].loss;
  block.parameter_blocks = others[0].blocks;
  block.manifolds = others[0].manifolds;
  ASSERT_TRUE(marginalizer->AddResidualBlock(block).ok());
  EXPECT_EQ(
      code(marginalizer->Marginalize(marginalized, {w.ego(1), w.extrinsic(), w.ego(2)}, &prior)),
      Code::kInvalidArgument);
  // The same block with another manifold in another residual.
  marginalizer->Clear();
  ceres::EuclideanManifold<ceres::DYNAMIC> euclidean19(19);
  for (const Term& t : terms) {
    block.cost_function = t.cost;
    block.loss_function = t.loss;
    block.parameter_blocks = t.blocks;
    block.manifolds = t.manifolds;
    if (t.cost == terms.back().cost) block.manifolds[0] = &euclidean19;
    ASSERT_TRUE(marginalizer->AddResidualBlock(block).ok());
  }
  EXPECT_EQ(code(marginalizer->Marginalize(marginalized, kept, &prior)), Code::kInvalidArgument);
}

// A loss whose value is not finite.
class NanLoss final : public ceres::LossFunction {
 public:
  void Evaluate(double, double rho[3]) const override { rho[0] = rho[1] = rho[2] = std::nan(""); }
};

TEST(Marginalizer, FailsWhenTheLinearizationIsNotFinite) {
  Sampler s(75);
  Eigen::VectorXd k = s.Gaussian(2, 1.0), m = s.Gaussian(2, 1.0);
  Eigen::VectorXd c = s.Gaussian(2, 1.0);
  const std::vector<Eigen::MatrixXd> A = {Eigen::MatrixXd::Identity(2, 2),
                                          Eigen::MatrixXd::Identity(2, 2)};
  const LinearCost finite(A, c);
  c[1] = std::nan("");
  const LinearCost not_finite(A, c);
  const NanLoss nan_loss;
  const auto code = [&](const ceres::CostFunction* cost, const ceres::LossFunction* loss) {
    Term term;
    term.cost = cost;
    term.loss = loss;
    term.blocks = {k.data(), m.data()};
    term.manifolds = {nullptr, nullptr};
    MarginalizationPrior prior;
    return Marginalize({term}, {m.data()}, {k.data()}, &prior).code();
  };
  EXPECT_EQ(code(&finite, nullptr), Status::Code::kOk);
  EXPECT_EQ(code(&not_finite, nullptr), Status::Code::kFailedPrecondition);
  EXPECT_EQ(code(&finite, &nan_loss), Status::Code::kFailedPrecondition);
}

TEST(MarginalizationPriorFactor, CreateRejectsInvalidPriors) {
  Window w(80, false);
  const std::vector<double*> marginalized = {w.ego(0)};
  MarginalizationPrior good;
  ASSERT_TRUE(
      Marginalize(w.Touching(marginalized), marginalized, {w.ego(1), w.extrinsic()}, &good).ok());
  std::unique_ptr<MarginalizationPriorFactor> factor;
  const MarginalizationPriorFactorOptions options;
  ASSERT_TRUE(MarginalizationPriorFactor::Create(good, options, &factor).ok());
  const auto rejected = [&](const MarginalizationPrior& prior,
                            const MarginalizationPriorFactorOptions& o) {
    std::unique_ptr<MarginalizationPriorFactor> f;
    const Status status = MarginalizationPriorFactor::Create(prior, o, &f);
    return status.code() == Status::Code::kInvalidArgument && f == nullptr;
  };

  MarginalizationPriorFactorOptions bad_options;
  bad_options.min_relative_eigenvalue = 2.0;
  EXPECT_TRUE(rejected(good, bad_options));
  MarginalizationPrior p = good;
  p.tangent_sizes.pop_back();
  EXPECT_TRUE(rejected(p, options));
  p = good;
  p.information.conservativeResize(23, 23);
  EXPECT_TRUE(rejected(p, options));
  p = good;
  p.gradient[3] = std::nan("");
  EXPECT_TRUE(rejected(p, options));
  p = good;
  p.linearization_points[1].resize(6);
  EXPECT_TRUE(rejected(p, options));
  p = good;
  p.information(0, 0) -= 2.0 * p.information.norm();  // indefinite
  EXPECT_TRUE(rejected(p, options));
  p = good;
  ceres::QuaternionManifold unsupported;
  p.manifolds[1] = &unsupported;
  p.ambient_sizes[1] = 4;
  p.tangent_sizes[1] = 3;
  p.linearization_points[1] = Eigen::Vector4d(0, 0, 0, 1);
  p.information = Eigen::MatrixXd::Identity(21, 21);
  p.gradient = Eigen::VectorXd::Zero(21);
  EXPECT_TRUE(rejected(p, options));
  p.manifolds[1] = nullptr;  // a 4-dim block cannot have a 3-dim Euclidean tangent
  EXPECT_TRUE(rejected(p, options));
}

}  // namespace
}  // namespace swarmlio::window::marginalization_test
