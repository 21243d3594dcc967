#include "swarmlio/lio/esikf_update.h"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <array>
#include <chrono>
#include <memory>
#include <utility>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "factors/prior_factor.h"

namespace swarmlio {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Undamped Gauss-Newton with Ceres's trust-region minimizer: one step per
// Solve, Levenberg-Marquardt with a radius of 1e16 so that the damping
// diag(J^T J) / radius is 1e-16 relative (docs/esikf.md).
ceres::Solver::Options GaussNewtonSolverOptions(const EsikfUpdateOptions& options) {
  ceres::Solver::Options s;
  s.minimizer_type = ceres::TRUST_REGION;
  s.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  s.initial_trust_region_radius = 1e16;
  s.max_trust_region_radius = 1e16;
  s.min_lm_diagonal = 1e-32;
  s.max_lm_diagonal = 1e32;
  s.min_relative_decrease = 0.0;  // accept every step that does not raise the cost
  s.max_num_iterations = 1;       // exactly one Gauss-Newton step per Solve
  s.function_tolerance = 0.0;     // never stop before taking the step
  s.gradient_tolerance = 0.0;
  s.parameter_tolerance = 0.0;
  s.linear_solver_type = options.linear_solver;
  s.dense_linear_algebra_library_type = ceres::EIGEN;
  s.num_threads = 1;
  s.minimizer_progress_to_stdout = false;
  s.logging_type = ceres::SILENT;
  return s;
}

// Ceres parameter storage of a SwarmState, in layout order.
class ParameterBlocks {
 public:
  explicit ParameterBlocks(const SwarmState& x) : teammates_(x.layout().NumTeammates()) {
    Write(x);
    pointers_.push_back(ego_.data());
    for (auto& t : teammates_) pointers_.push_back(t.data());
  }
  void Write(const SwarmState& x) {
    x.ego.ToParameters(ego_.data());
    const std::vector<int>& ids = x.layout().teammate_ids();
    for (size_t s = 0; s < ids.size(); ++s) x.teammate(ids[s]).ToParameters(teammates_[s].data());
  }
  SwarmState Read(SwarmState x) const {
    x.ego = EgoState::FromParameters(ego_.data());
    const std::vector<int>& ids = x.layout().teammate_ids();
    for (size_t s = 0; s < ids.size(); ++s) {
      x.teammate(ids[s]) = GlobalExtrinsic::FromParameters(teammates_[s].data());
    }
    return x;
  }
  const std::vector<double*>& pointers() const { return pointers_; }

 private:
  std::array<double, EgoState::kAmbientSize> ego_{};
  std::vector<std::array<double, GlobalExtrinsic::kAmbientSize>> teammates_;
  std::vector<double*> pointers_;
};

bool StepIsSmall(const Eigen::VectorXd& dx,
                 const ErrorStateLayout& layout,
                 const EsikfUpdateOptions& options) {
  const auto below = [&dx](const Segment& s, double threshold) {
    return dx.segment(s.offset, s.size).norm() < threshold;
  };
  bool small = below(ErrorStateLayout::kRotation, options.convergence_rotation_rad) &&
               below(ErrorStateLayout::kPosition, options.convergence_translation_m);
  for (int id : layout.teammate_ids()) {
    small = small && below(layout.TeammateRotation(id), options.convergence_rotation_rad) &&
            below(layout.TeammateTranslation(id), options.convergence_translation_m);
  }
  return small;
}

// (J^T J)^-1 at x with J = [prior tangent Jacobian; point-to-plane H].
bool PosteriorCovariance(const PriorFactor& prior,
                         const PointToPlaneFactor& points,
                         bool with_points,
                         const SwarmState& x,
                         Eigen::MatrixXd* P) {
  const Eigen::MatrixXd J_prior = prior.TangentJacobian(x);
  Eigen::MatrixXd information = J_prior.transpose() * J_prior;
  if (with_points) {
    Eigen::Matrix<double, 6, 6> HtH = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Htz = Eigen::Matrix<double, 6, 1>::Zero();
    points.AccumulateNormalEquations(x.ego, &HtH, &Htz);
    static_assert(ErrorStateLayout::kRotation.offset == 0 &&
                  ErrorStateLayout::kPosition.offset == 3);
    information.topLeftCorner<6, 6>() += HtH;
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(information);
  if (llt.info() != Eigen::Success) return false;
  *P = llt.solve(Eigen::MatrixXd::Identity(x.Dim(), x.Dim()));
  *P = 0.5 * (*P + P->transpose());
  return true;
}

}  // namespace

std::string EsikfUpdateOptions::Validate() const {
  const std::string fields = config::ValidateFields(*this);
  if (!fields.empty()) return fields;
  if (linear_solver != ceres::DENSE_NORMAL_CHOLESKY && linear_solver != ceres::DENSE_QR) {
    return "linear_solver: must be DENSE_NORMAL_CHOLESKY or DENSE_QR";
  }
  return "";
}

EsikfUpdate::EsikfUpdate(EsikfUpdateOptions options) : options_(std::move(options)) {}

EsikfUpdateResult EsikfUpdate::Run(const SwarmState& x_hat,
                                   const Eigen::MatrixXd& P_hat,
                                   const PlaneAssociationFn& associate) const {
  return RunFrom(x_hat, P_hat, x_hat, associate);
}

EsikfUpdateResult EsikfUpdate::RunFrom(const SwarmState& x_hat,
                                       const Eigen::MatrixXd& P_hat,
                                       const SwarmState& x_start,
                                       const PlaneAssociationFn& associate) const {
  const Clock::time_point t_start = Clock::now();
  EsikfUpdateResult result;
  result.state = x_hat;
  result.covariance = P_hat;
  const auto fail = [&](Status status) {
    result.status = std::move(status);
    result.total_time_s = SecondsSince(t_start);
    return result;
  };
  if (const std::string invalid = options_.Validate(); !invalid.empty()) {
    return fail(Status::InvalidArgument("EsikfUpdateOptions." + invalid));
  }
  if (x_start.layout() != x_hat.layout()) {
    return fail(Status::InvalidArgument("EsikfUpdate: x_start and x_hat have different layouts"));
  }
  if (!associate) return fail(Status::InvalidArgument("EsikfUpdate: no association callback"));
  Eigen::MatrixXd cholesky;
  if (P_hat.rows() != x_hat.Dim() || !PriorFactor::CholeskyOfCovariance(P_hat, &cholesky)) {
    return fail(Status::InvalidArgument(
        "EsikfUpdate: P_hat must be a " + std::to_string(x_hat.Dim()) + "x" +
        std::to_string(x_hat.Dim()) + " symmetric positive-definite matrix"));
  }

  // Everything the problem points to outlives it (declared before it).
  EgoStateManifold ego_manifold;
  GlobalExtrinsicManifold teammate_manifold;
  PriorFactor prior(x_hat, std::move(cholesky));
  std::vector<PlaneCorrespondence> correspondences;
  PointToPlaneFactor points(&correspondences);
  ParameterBlocks blocks(x_start);

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const std::vector<double*>& pointers = blocks.pointers();
  problem.AddParameterBlock(pointers[0], EgoState::kAmbientSize, &ego_manifold);
  for (size_t b = 1; b < pointers.size(); ++b) {
    problem.AddParameterBlock(pointers[b], GlobalExtrinsic::kAmbientSize, &teammate_manifold);
  }
  problem.AddResidualBlock(&prior, nullptr, pointers);
  ceres::ResidualBlockId point_block = nullptr;

  const ceres::Solver::Options solver_options = GaussNewtonSolverOptions(options_);
  SwarmState x = x_start;
  for (int it = 0; it < options_.max_iterations; ++it) {
    // Re-associate at the current estimate and swap the point residual block.
    const Clock::time_point t_assoc = Clock::now();
    correspondences.clear();
    const Status assoc = associate(x, &correspondences);
    result.association_time_s += SecondsSince(t_assoc);
    if (!assoc.ok()) return fail(assoc.WithContext("EsikfUpdate: association"));
    if (point_block != nullptr) {
      problem.RemoveResidualBlock(point_block);
      point_block = nullptr;
    }
    points.SyncNumResiduals();
    if (!correspondences.empty()) {
      point_block = problem.AddResidualBlock(&points, nullptr, pointers[0]);
    }
    result.num_correspondences = static_cast<int>(correspondences.size());

    const Clock::time_point t_solve = Clock::now();
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    result.solve_time_s += SecondsSince(t_solve);
    if (!summary.IsSolutionUsable()) {
      return fail(Status::Internal("EsikfUpdate: Ceres failed: " + summary.message));
    }
    result.num_rejected_steps += summary.num_unsuccessful_steps;
    ++result.iterations;

    const SwarmState x_next = blocks.Read(x);
    const Eigen::VectorXd dx = x_next.BoxMinus(x);
    x = x_next;
    if (summary.num_unsuccessful_steps > 0) break;  // Ceres refused the GN step
    if (StepIsSmall(dx, x.layout(), options_)) {
      result.converged = true;
      break;
    }
  }

  const Clock::time_point t_cov = Clock::now();
  Eigen::MatrixXd P;
  if (!PosteriorCovariance(prior, points, point_block != nullptr, x, &P)) {
    return fail(Status::Internal("EsikfUpdate: posterior information is not positive definite"));
  }
  result.covariance_time_s = SecondsSince(t_cov);
  result.state = std::move(x);
  result.covariance = std::move(P);
  result.total_time_s = SecondsSince(t_start);
  return result;
}

}  // namespace swarmlio
