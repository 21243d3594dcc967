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
#include "swarmlio/window/marginalization.h"

#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "factors/active_observation_factor.h"
#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "factors/imu_preintegration_factor.h"
#include "factors/marginalization_prior_factor.h"
#include "factors/passive_observation_factor.h"
#include "factors/pose_information_factor.h"
#include "factors/prior_factor.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"

namespace swarmlio {
namespace {

constexpr double kTolerance = 1e-9;  // relative, (a) and (b)

class Sampler {
 public:
  explicit Sampler(unsigned seed) : rng_(seed) {}
  double Normal() { return normal_(rng_); }
  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  Eigen::Vector3d Gaussian3(double scale) {
    return scale * Eigen::Vector3d(Normal(), Normal(), Normal());
  }
  Eigen::VectorXd Gaussian(int n, double scale) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v[i] = scale * Normal();
    return v;
  }
  Eigen::Quaterniond Rotation() {
    return Eigen::Quaterniond(Eigen::Vector4d(Normal(), Normal(), Normal(), Normal()).normalized());
  }
  // Symmetric positive definite, eigenvalues log-uniform in [lo, hi].
  Eigen::MatrixXd Spd(int n, double lo, double hi) {
    Eigen::MatrixXd A(n, n);
    for (int i = 0; i < n * n; ++i) A.data()[i] = Normal();
    const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ();
    Eigen::VectorXd l(n);
    for (int i = 0; i < n; ++i) l[i] = std::exp(Uniform(std::log(lo), std::log(hi)));
    return Q * l.asDiagonal() * Q.transpose();
  }
  EgoState Ego() {
    EgoState ego;
    ego.q_G_b = Rotation();
    ego.p_b_in_G = Gaussian3(5.0);
    ego.v_b_in_G = Gaussian3(1.0);
    ego.gyro_bias = Gaussian3(0.01);
    ego.accel_bias = Gaussian3(0.1);
    ego.g_in_G += Gaussian3(0.05);
    return ego;
  }
  GlobalExtrinsic Extrinsic() {
    GlobalExtrinsic T;
    T.q_Gi_Gj = Rotation();
    T.p_Gj_in_Gi = Gaussian3(10.0);
    return T;
  }
  EgoState Perturb(const EgoState& ego, double scale) {
    return ego.BoxPlus(Gaussian(EgoState::kTangentSize, scale));
  }
  GlobalExtrinsic Perturb(const GlobalExtrinsic& T, double scale) {
    return T.BoxPlus(Gaussian(GlobalExtrinsic::kTangentSize, scale));
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> normal_;
};

// For RecordProperty (--gtest_output=xml): the achieved errors.
std::string Scientific(double value) {
  std::ostringstream os;
  os << std::scientific << std::setprecision(2) << value;
  return os.str();
}

double RelativeError(const Eigen::MatrixXd& value, const Eigen::MatrixXd& reference) {
  return (value - reference).norm() / reference.norm();
}

// One residual block as it is added to a ceres::Problem.
struct Term {
  const ceres::CostFunction* cost = nullptr;
  const ceres::LossFunction* loss = nullptr;
  std::vector<double*> blocks;
  std::vector<const ceres::Manifold*> manifolds;

  bool TouchesAny(const std::vector<double*>& list) const {
    for (double* b : blocks) {
      if (std::find(list.begin(), list.end(), b) != list.end()) return true;
    }
    return false;
  }
};

// The tangent-space linear system of `terms` at the current values, columns
// in `order`, linearized by Ceres (losses applied).
struct LinearSystem {
  Eigen::MatrixXd H;  // J^T J
  Eigen::VectorXd g;  // J^T r
  double cost = 0.0;
};

LinearSystem Linearize(const std::vector<Term>& terms, const std::vector<double*>& order) {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  std::set<double*> has_manifold;
  for (const Term& t : terms) {
    problem.AddResidualBlock(const_cast<ceres::CostFunction*>(t.cost),
                             const_cast<ceres::LossFunction*>(t.loss), t.blocks);
    for (size_t i = 0; i < t.blocks.size(); ++i) {
      if (t.manifolds[i] != nullptr && has_manifold.insert(t.blocks[i]).second) {
        problem.SetManifold(t.blocks[i], const_cast<ceres::Manifold*>(t.manifolds[i]));
      }
    }
  }
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = order;
  LinearSystem out;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  EXPECT_TRUE(problem.Evaluate(evaluate, &out.cost, &residuals, nullptr, &crs));
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) J(row, crs.cols[k]) = crs.values[k];
  }
  const Eigen::Map<const Eigen::VectorXd> r(residuals.data(), crs.num_rows);
  out.H = J.transpose() * J;
  out.g = J.transpose() * r;
  return out;
}

// The window of the tests: ego states x0, x1, x2 of one drone and its global
// extrinsic T to one teammate, at a linearization point where no residual is
// zero:
//   prior(x0, T), imu(x0, x1), active(x0, T) twice, imu(x1, x2),
//   passive(x1, T), active(x2, T), pose information(x2).
// With losses: Huber on the first and Tolerant (rho'' > 0) on the second
// active observation of x0.
class Window {
 public:
  Window(unsigned seed, bool with_losses) {
    Sampler s(seed);
    std::array<EgoState, 3> truth = {s.Ego(), s.Ego(), s.Ego()};
    for (int k = 1; k < 3; ++k) truth[k].g_in_G = truth[0].g_in_G + s.Gaussian3(0.01);
    const GlobalExtrinsic T_truth = s.Extrinsic();
    for (int k = 0; k < 3; ++k) {
      lin_[k] = s.Perturb(truth[k], 0.05);
      lin_[k].ToParameters(ego_[k].data());
    }
    T_lin_ = s.Perturb(T_truth, 0.05);
    T_lin_.ToParameters(extrinsic_.data());

    // prior(x0, T)
    SwarmState x_hat;
    x_hat.ego = s.Perturb(truth[0], 0.05);
    x_hat.AddTeammate(1, s.Perturb(T_truth, 0.05));
    Eigen::MatrixXd U;
    EXPECT_TRUE(PriorFactor::CholeskyOfCovariance(s.Spd(24, 1e-3, 1e-1), &U));
    Add(std::make_unique<PriorFactor>(x_hat, U), nullptr, {ego(0), extrinsic()});

    AddImu(&s, truth, 0);
    AddActive(&s, truth[0], T_truth, 0, with_losses ? Loss::kHuber : Loss::kNone);
    AddActive(&s, truth[0], T_truth, 0, with_losses ? Loss::kTolerant : Loss::kNone);
    AddImu(&s, truth, 1);

    // passive(x1, T)
    const Eigen::Matrix3d R_Gj_bj = s.Rotation().toRotationMatrix();
    const Eigen::Vector3d p_bj_in_Gj = s.Gaussian3(8.0);
    const Eigen::Matrix3d Sigma_obs = s.Spd(3, 1e-3, 1e-2);
    const Eigen::Matrix3d Sigma_theta = s.Spd(3, 1e-5, 1e-4);
    const Eigen::Matrix3d Sigma_p = s.Spd(3, 1e-3, 1e-2);
    const PassiveObservationFactor draft(Eigen::Vector3d::Zero(), 0.02, R_Gj_bj, p_bj_in_Gj,
                                         Sigma_obs, Sigma_theta, Sigma_p, lin_[1], T_lin_);
    const Eigen::Vector3d z = draft.Predict(truth[1], T_truth) + s.Gaussian3(0.05);
    Add(std::make_unique<PassiveObservationFactor>(z, 0.02, R_Gj_bj, p_bj_in_Gj, Sigma_obs,
                                                   Sigma_theta, Sigma_p, lin_[1], T_lin_),
        nullptr, {ego(1), extrinsic()});

    AddActive(&s, truth[2], T_truth, 2, Loss::kNone);

    // pose information(x2)
    auto pose = std::make_unique<PoseInformationFactor>();
    pose->Set(s.Spd(6, 1.0, 100.0), s.Gaussian(6, 1.0), truth[2].q_G_b, truth[2].p_b_in_G);
    Add(std::move(pose), nullptr, {ego(2)});
  }
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  double* ego(int k) { return ego_[k].data(); }
  double* extrinsic() { return extrinsic_.data(); }
  const std::vector<Term>& terms() const { return terms_; }
  std::vector<Term> Touching(const std::vector<double*>& blocks) const {
    std::vector<Term> out;
    for (const Term& t : terms_) {
      if (t.TouchesAny(blocks)) out.push_back(t);
    }
    return out;
  }
  std::vector<Term> NotTouching(const std::vector<double*>& blocks) const {
    std::vector<Term> out;
    for (const Term& t : terms_) {
      if (!t.TouchesAny(blocks)) out.push_back(t);
    }
    return out;
  }
  std::vector<double*> AllBlocks() { return {ego(0), ego(1), ego(2), extrinsic()}; }
  const ceres::Manifold* ManifoldOf(const double* block) const {
    if (block == extrinsic_.data()) return &extrinsic_manifold_;
    return &ego_manifold_;
  }

 private:
  void Add(std::unique_ptr<ceres::CostFunction> cost,
           std::unique_ptr<ceres::LossFunction> loss,
           std::vector<double*> blocks) {
    Term t;
    t.cost = cost.get();
    t.loss = loss.get();
    t.blocks = std::move(blocks);
    for (double* b : t.blocks) t.manifolds.push_back(ManifoldOf(b));
    terms_.push_back(t);
    costs_.push_back(std::move(cost));
    if (loss) losses_.push_back(std::move(loss));
  }

  // IMU preintegration between ego k and k+1, Deltas from the truth plus noise.
  void AddImu(Sampler* s, const std::array<EgoState, 3>& truth, int k) {
    const EgoState& a = truth[k];
    const EgoState& b = truth[k + 1];
    const double T = 0.1;
    PreintegratedImu pre;
    pre.dt_s = T;
    const Eigen::Matrix3d Ra = a.R_G_b();
    pre.delta_R = Ra.transpose() * b.R_G_b() * so3::Exp(s->Gaussian3(0.01));
    pre.delta_v = Ra.transpose() * (b.v_b_in_G - a.v_b_in_G - a.g_in_G * T) + s->Gaussian3(0.01);
    pre.delta_p =
        Ra.transpose() * (b.p_b_in_G - a.p_b_in_G - a.v_b_in_G * T - 0.5 * a.g_in_G * T * T) +
        s->Gaussian3(0.01);
    pre.gyro_bias_lin = a.gyro_bias + s->Gaussian3(1e-3);
    pre.accel_bias_lin = a.accel_bias + s->Gaussian3(1e-2);
    const auto random3 = [s](double scale) {
      const Eigen::VectorXd v = s->Gaussian(9, scale);
      return Eigen::Matrix3d(Eigen::Map<const Eigen::Matrix3d>(v.data()));
    };
    pre.dR_dbg = -T * Eigen::Matrix3d::Identity() + random3(0.01);
    pre.dv_dbg = random3(0.01);
    pre.dv_dba = -T * Eigen::Matrix3d::Identity();
    pre.dp_dbg = random3(0.001);
    pre.dp_dba = -0.5 * T * T * Eigen::Matrix3d::Identity();
    pre.covariance = s->Spd(18, 1e-4, 1e-2);
    std::unique_ptr<ImuPreintegrationFactor> factor;
    EXPECT_TRUE(ImuPreintegrationFactor::Create(pre, &factor).ok());
    Add(std::move(factor), nullptr, {ego(k), ego(k + 1)});
  }

  // Active observation of the teammate from ego k. The loss is sized by the
  // squared residual s at the linearization point: Huber in its linear part
  // (rho'' < 0: r and J only scaled), Tolerant at its inflection (rho'' > 0:
  // the full correction of J, alpha = 1 - sqrt(3)).
  enum class Loss { kNone, kHuber, kTolerant };
  void AddActive(
      Sampler* s, const EgoState& truth, const GlobalExtrinsic& T_truth, int k, Loss kind) {
    const Eigen::Vector3d p_bj_in_Gj = s->Gaussian3(8.0);
    const Eigen::Vector3d z = truth.R_G_b().transpose() * (T_truth.R_Gi_Gj() * p_bj_in_Gj +
                                                           T_truth.p_Gj_in_Gi - truth.p_b_in_G) +
                              s->Gaussian3(0.05);
    auto factor = std::make_unique<ActiveObservationFactor>(z, p_bj_in_Gj, s->Spd(3, 1e-3, 1e-2),
                                                            s->Spd(3, 1e-3, 1e-2), lin_[k].R_G_b(),
                                                            T_lin_.R_Gi_Gj());
    const double squared_norm = factor->Residual(lin_[k], T_lin_).squaredNorm();
    std::unique_ptr<ceres::LossFunction> loss;
    if (kind == Loss::kHuber) {
      loss = std::make_unique<ceres::HuberLoss>(0.5 * std::sqrt(squared_norm));
    }
    if (kind == Loss::kTolerant) {
      loss = std::make_unique<ceres::TolerantLoss>(squared_norm, 0.5 * squared_norm);
    }
    Add(std::move(factor), std::move(loss), {ego(k), extrinsic()});
  }

  std::array<EgoState, 3> lin_;
  GlobalExtrinsic T_lin_;
  std::array<std::array<double, EgoState::kAmbientSize>, 3> ego_;
  std::array<double, GlobalExtrinsic::kAmbientSize> extrinsic_;
  EgoStateManifold ego_manifold_;
  GlobalExtrinsicManifold extrinsic_manifold_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  std::vector<std::unique_ptr<ceres::LossFunction>> losses_;
  std::vector<Term> terms_;
};

Status Marginalize(const std::vector<Term>& terms,
                   const std::vector<double*>& marginalized,
                   const std::vector<double*>& kept,
                   MarginalizationPrior* prior) {
  std::unique_ptr<Marginalizer> marginalizer;
  SWARMLIO_RETURN_IF_ERROR(Marginalizer::Create(MarginalizationOptions(), &marginalizer));
  for (const Term& t : terms) {
    MarginalizationResidualBlock block;
    block.cost_function = t.cost;
    block.loss_function = t.loss;
    block.parameter_blocks = t.blocks;
    block.manifolds = t.manifolds;
    SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(block));
  }
  return marginalizer->Marginalize(marginalized, kept, prior);
}

std::unique_ptr<MarginalizationPriorFactor> PriorFactorOf(const MarginalizationPrior& prior) {
  std::unique_ptr<MarginalizationPriorFactor> factor;
  const Status status =
      MarginalizationPriorFactor::Create(prior, MarginalizationPriorFactorOptions(), &factor);
  EXPECT_TRUE(status.ok()) << status.message();
  return factor;
}

// The two marginalizations of the tests.
struct Case {
  const char* name;
  bool marginalize_extrinsic;  // {x0} -> kept {x1, T}; or {x0, T} -> kept {x1, x2}
  bool with_losses;
};
const Case kCases[] = {{"x0", false, false},
                       {"x0 with losses", false, true},
                       {"x0 and T", true, false},
                       {"x0 and T with losses", true, true}};

struct Split {
  std::vector<double*> marginalized, kept;
};
Split SplitOf(Window* w, const Case& c) {
  if (c.marginalize_extrinsic) return {{w->ego(0), w->extrinsic()}, {w->ego(1), w->ego(2)}};
  return {{w->ego(0)}, {w->ego(1), w->extrinsic()}};
}

// (a) (H*)^-1 is the dense Gaussian marginal of the kept blocks, and b* the
// dense elimination: with dx = -H^-1 g of the marginalized residuals,
// H* dx_k = -b*. When x0 and T are marginalized, those residuals see x2
// through one 3-row observation only, so their H is singular and has no
// dense inverse; a known unit information R on the kept blocks is then added
// to both sides (the Schur complement of H + R_kk is H* + R_kk, with the same b*).
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
}  // namespace swarmlio
