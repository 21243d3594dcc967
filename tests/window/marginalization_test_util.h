// Shared by the Marginalizer / MarginalizationPriorFactor tests
// (marginalization_test.cc, marginalization_errors_test.cc): a window of
// three ego states and one global extrinsic linked by the project's factors,
// linearized by Ceres itself, and the dense reference computations.
#pragma once

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
#include "swarmlio/window/marginalization.h"

namespace swarmlio::window::marginalization_test {

inline constexpr double kTolerance = 1e-9;  // relative, (a) and (b)

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
    T.q_Ga_Gb = Rotation();
    T.p_Gb_in_Ga = Gaussian3(10.0);
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
inline std::string Scientific(double value) {
  std::ostringstream os;
  os << std::scientific << std::setprecision(2) << value;
  return os.str();
}

inline double RelativeError(const Eigen::MatrixXd& value, const Eigen::MatrixXd& reference) {
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

inline LinearSystem Linearize(const std::vector<Term>& terms, const std::vector<double*>& order) {
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
    const Eigen::Vector3d z = truth.R_G_b().transpose() * (T_truth.R_Ga_Gb() * p_bj_in_Gj +
                                                           T_truth.p_Gb_in_Ga - truth.p_b_in_G) +
                              s->Gaussian3(0.05);
    auto factor = std::make_unique<ActiveObservationFactor>(z, p_bj_in_Gj, s->Spd(3, 1e-3, 1e-2),
                                                            s->Spd(3, 1e-3, 1e-2), lin_[k].R_G_b(),
                                                            T_lin_.R_Ga_Gb());
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

inline Status Marginalize(const std::vector<Term>& terms,
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

inline std::unique_ptr<MarginalizationPriorFactor> PriorFactorOf(
    const MarginalizationPrior& prior) {
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
inline const Case kCases[] = {{"x0", false, false},
                              {"x0 with losses", false, true},
                              {"x0 and T", true, false},
                              {"x0 and T with losses", true, true}};

struct Split {
  std::vector<double*> marginalized, kept;
};
inline Split SplitOf(Window* w, const Case& c) {
  if (c.marginalize_extrinsic) return {{w->ego(0), w->extrinsic()}, {w->ego(1), w->ego(2)}};
  return {{w->ego(0)}, {w->ego(1), w->extrinsic()}};
}

// (a) (H*)^-1 is the dense Gaussian marginal of the kept blocks, and b* the
// dense elimination: with dx = -H^-1 g of the marginalized residuals,
// H* dx_k = -b*. When x0 and T are marginalized, those residuals see x2
// through one 3-row observation only, so their H is singular and has no
// dense inverse; a known unit information R on the kept blocks is then added
// to both sides (the Schur complement of H + R_kk is H* + R_kk, with the same b*).

}  // namespace swarmlio::window::marginalization_test
