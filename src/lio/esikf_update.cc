#include "swarmlio/lio/esikf_update.h"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "factors/prior_factor.h"
#include "factors/term_linearizer.h"
#include "src/lio/esikf_teammate_subset.h"
#include "swarmlio/common/stopwatch.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::lio {

using internal::Complement;
using internal::Gather;
using internal::RestoreConsideredCovariance;
using internal::ScatterCovariance;
using internal::SchmidtKalmanCrossCovariance;
using internal::SelectTeammates;
using internal::SubsetIndices;
using internal::SubsetState;
namespace {

using Clock = std::chrono::steady_clock;

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

}  // namespace

namespace {

// J^T J of one residual block at the parameter values it points to (tangent
// Jacobians, factors/term_linearizer.h), placed at the block's columns of the
// layout.
bool AddTermInformation(const ResidualTerm& term, const std::vector<double*>& pointers,
                        const ErrorStateLayout& layout, const ceres::Manifold& ego_manifold,
                        const ceres::Manifold& teammate_manifold, Eigen::MatrixXd* information) {
  const int m = term.cost->num_residuals();
  const size_t nb = term.blocks.size();
  std::vector<const double*> params(nb);
  std::vector<int> offsets(nb), tangent(nb);
  std::vector<const ceres::Manifold*> manifolds(nb);
  for (size_t b = 0; b < nb; ++b) {
    // The keys resolved when the term entered the problem (AddMeasurementBlocks).
    const StateKey& key = term.blocks[b];
    const bool ego = key.is_ego();
    const int id = key.teammate_id();
    params[b] = ego ? pointers[0] : pointers[static_cast<size_t>(layout.SlotOf(id)) + 1];
    offsets[b] = ego ? 0 : layout.TeammateBlock(id).offset;
    manifolds[b] = ego ? &ego_manifold : &teammate_manifold;
    tangent[b] = manifolds[b]->TangentSize();
  }
  Eigen::VectorXd residuals;
  std::vector<Eigen::MatrixXd> tangent_jacobians;
  if (!LinearizeTerm(*term.cost, params.data(), manifolds, &residuals, &tangent_jacobians).ok()) {
    return false;
  }
  int cols = 0;
  for (size_t b = 0; b < nb; ++b) cols += tangent[b];
  Eigen::MatrixXd J(m, cols);
  int c = 0;
  for (size_t b = 0; b < nb; ++b) {
    J.middleCols(c, tangent[b]) = tangent_jacobians[b];
    c += tangent[b];
  }
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  int ci = 0;
  for (size_t a = 0; a < nb; ++a) {
    int cj = 0;
    for (size_t b = 0; b < nb; ++b) {
      information->block(offsets[a], offsets[b], tangent[a], tangent[b]) +=
          JtJ.block(ci, cj, tangent[a], tangent[b]);
      cj += tangent[b];
    }
    ci += tangent[a];
  }
  return true;
}

// RunAll's input checks; on success *cholesky is the Cholesky factor of
// P_hat that the prior takes.
Status CheckRunInputs(const EsikfUpdateOptions& options,
                      const SwarmState& x_hat,
                      const Eigen::MatrixXd& P_hat,
                      const SwarmState& x_start,
                      const std::vector<MeasurementModel*>& models,
                      Eigen::MatrixXd* cholesky) {
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("EsikfUpdateOptions." + invalid);
  }
  if (x_start.layout() != x_hat.layout()) {
    return Status::InvalidArgument("EsikfUpdate: x_start and x_hat have different layouts");
  }
  for (const MeasurementModel* m : models) {
    if (m == nullptr) return Status::InvalidArgument("EsikfUpdate: null measurement model");
  }
  if (P_hat.rows() != x_hat.Dim() || !PriorFactor::CholeskyOfCovariance(P_hat, cholesky)) {
    return Status::InvalidArgument("EsikfUpdate: P_hat must be a " + std::to_string(x_hat.Dim()) +
                                   "x" + std::to_string(x_hat.Dim()) +
                                   " symmetric positive-definite matrix");
  }
  return Status::Ok();
}

// A problem that points to cost functions and manifolds its caller owns.
ceres::Problem::Options NonOwningProblemOptions() {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = true;
  return problem_options;
}

// The models' residual blocks at the current linearization point.
struct MeasurementBlocks {
  std::vector<ResidualTerm> terms;
  std::vector<size_t> model_terms;  // terms of model k: [model_terms[k], model_terms[k + 1])
  std::vector<ceres::ResidualBlockId> ids;  // in the problem, one per term
};

// The Ceres problem of one update: the state's parameter blocks (ego, then
// the teammates in slot order) on their manifolds, the prior, and the
// measurement blocks of the current linearization. Everything the problem
// points to outlives it (declared before it).
struct UpdateProblem {
  UpdateProblem(const SwarmState& x_hat, Eigen::MatrixXd cholesky, const SwarmState& x)
      : prior(x_hat, std::move(cholesky)), blocks(x), problem(NonOwningProblemOptions()) {
    const std::vector<double*>& pointers = blocks.pointers();
    problem.AddParameterBlock(pointers[0], EgoState::kAmbientSize, &ego_manifold);
    for (size_t b = 1; b < pointers.size(); ++b) {
      problem.AddParameterBlock(pointers[b], GlobalExtrinsic::kAmbientSize, &teammate_manifold);
    }
    problem.AddResidualBlock(&prior, nullptr, pointers);
  }

  EgoStateManifold ego_manifold;
  GlobalExtrinsicManifold teammate_manifold;
  PriorFactor prior;
  ParameterBlocks blocks;
  MeasurementBlocks measurements;
  ceres::Problem problem;
};

// The parameter block `key` names among `pointers` (the ego state, then the
// teammates in `layout`'s slot order). The filter holds one ego state: Ego()
// and EgoAt(t) for t the stamp of the scan being updated (`stamp_ns`, if
// known) resolve to it; any other EgoAt, or a teammate absent from the
// layout, is InvalidArgument naming the key.
Status ResolveKey(const StateKey& key, const std::vector<double*>& pointers,
                  const ErrorStateLayout& layout, std::optional<int64_t> stamp_ns,
                  double** block) {
  switch (key.kind()) {
    case StateKey::Kind::kEgo:
      *block = pointers[0];
      return Status::Ok();
    case StateKey::Kind::kEgoAt:
      if (stamp_ns.has_value() && key.stamp_ns() == *stamp_ns) {
        *block = pointers[0];
        return Status::Ok();
      }
      return Status::InvalidArgument(
          "EsikfUpdate: a residual block names " + key.ToString() +
          "; the filter holds only the state at " +
          (stamp_ns.has_value() ? std::to_string(*stamp_ns) + " ns" : "the scan being updated"));
    case StateKey::Kind::kTeammateExtrinsic:
      break;
  }
  if (!layout.HasTeammate(key.teammate_id())) {
    return Status::InvalidArgument("EsikfUpdate: a residual block names teammate " +
                                   std::to_string(key.teammate_id()) +
                                   ", absent from the estimated state");
  }
  *block = pointers[static_cast<size_t>(layout.SlotOf(key.teammate_id())) + 1];
  return Status::Ok();
}

// Adds one residual block per term of `measurements` to `problem`, on the
// parameter blocks (`pointers`, in `layout`'s slot order) the term names.
Status AddMeasurementBlocks(const std::vector<double*>& pointers,
                            const ErrorStateLayout& layout,
                            std::optional<int64_t> stamp_ns,
                            ceres::Problem* problem,
                            MeasurementBlocks* measurements) {
  std::vector<double*> term_pointers;
  for (const ResidualTerm& term : measurements->terms) {
    term_pointers.clear();
    for (const StateKey& key : term.blocks) {
      double* block = nullptr;
      SWARMLIO_RETURN_IF_ERROR(ResolveKey(key, pointers, layout, stamp_ns, &block));
      term_pointers.push_back(block);
    }
    if (term.cost == nullptr || term.cost->parameter_block_sizes().size() != term_pointers.size()) {
      return Status::InvalidArgument(
          "EsikfUpdate: a residual block's cost does not match its block list");
    }
    measurements->ids.push_back(problem->AddResidualBlock(
        const_cast<ceres::CostFunction*>(term.cost), nullptr, term_pointers));
  }
  return Status::Ok();
}

// Drops last iteration's measurement blocks, re-linearizes every model at x
// (timed into *association_time_s) and adds the new blocks to the problem.
Status Relinearize(const std::vector<MeasurementModel*>& models,
                   const SwarmState& x,
                   std::optional<int64_t> stamp_ns,
                   UpdateProblem* up,
                   double* association_time_s) {
  ceres::Problem* problem = &up->problem;
  MeasurementBlocks* measurements = &up->measurements;
  for (ceres::ResidualBlockId id : measurements->ids) problem->RemoveResidualBlock(id);
  measurements->ids.clear();
  measurements->terms.clear();
  measurements->model_terms.assign(1, 0);
  const Clock::time_point t_assoc = Clock::now();
  for (MeasurementModel* model : models) {
    const Status status = model->Linearize(x, &measurements->terms);
    measurements->model_terms.push_back(measurements->terms.size());
    if (!status.ok()) {
      *association_time_s += SecondsSince(t_assoc);
      return status.WithContext(std::string("EsikfUpdate: ") + model->name());
    }
  }
  *association_time_s += SecondsSince(t_assoc);
  return AddMeasurementBlocks(up->blocks.pointers(), x.layout(), stamp_ns, problem, measurements);
}

// Posterior (J^T J)^-1 at the final estimate x (the parameter blocks hold
// its values): the tangent Jacobian of every residual block, columns in
// ErrorStateLayout order. The prior's in closed form; a model's through its
// fast path (AddInformation) when it has one, else from its blocks'
// Jacobians and the manifolds' PlusJacobian.
Status PosteriorCovariance(const UpdateProblem& up,
                           const SwarmState& x,
                           const std::vector<MeasurementModel*>& models,
                           Eigen::MatrixXd* covariance) {
  const MeasurementBlocks& measurements = up.measurements;
  const Eigen::MatrixXd J_prior = up.prior.TangentJacobian(x);
  Eigen::MatrixXd information = J_prior.transpose() * J_prior;
  for (size_t k = 0; k < models.size(); ++k) {
    if (models[k]->AddInformation(x, &information)) continue;
    for (size_t t = measurements.model_terms[k]; t < measurements.model_terms[k + 1]; ++t) {
      if (!AddTermInformation(measurements.terms[t], up.blocks.pointers(), x.layout(),
                              up.ego_manifold, up.teammate_manifold, &information)) {
        return Status::Internal("EsikfUpdate: Jacobian evaluation failed");
      }
    }
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(information);
  if (llt.info() != Eigen::Success) {
    return Status::Internal("EsikfUpdate: posterior information is not positive definite");
  }
  Eigen::MatrixXd P = llt.solve(Eigen::MatrixXd::Identity(x.Dim(), x.Dim()));
  P = 0.5 * (P + P.transpose());
  *covariance = std::move(P);
  return Status::Ok();
}

// The sub-update's counters and timings.
void CopyRunStatistics(const EsikfUpdateResult& sub, EsikfUpdateResult* result) {
  result->status = sub.status;
  result->iterations = sub.iterations;
  result->converged = sub.converged;
  result->num_residual_blocks = sub.num_residual_blocks;
  result->num_rejected_steps = sub.num_rejected_steps;
  result->association_time_s = sub.association_time_s;
  result->solve_time_s = sub.solve_time_s;
  result->covariance_time_s = sub.covariance_time_s;
  result->total_time_s = sub.total_time_s;
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
  if (!associate) {
    EsikfUpdateResult result;
    result.state = x_hat;
    result.covariance = P_hat;
    result.status = Status::InvalidArgument("EsikfUpdate: no association callback");
    return result;
  }
  PlaneMeasurementModel planes(associate);
  EsikfUpdateResult result = RunFrom(x_hat, P_hat, x_start, {&planes});
  result.num_correspondences = static_cast<int>(planes.correspondences().size());
  return result;
}

EsikfUpdateResult EsikfUpdate::Run(const SwarmState& x_hat, const Eigen::MatrixXd& P_hat,
                                   const std::vector<MeasurementModel*>& models,
                                   const std::vector<int>* estimated_teammates,
                                   const std::vector<int>* considered_teammates,
                                   std::optional<int64_t> stamp_ns) const {
  return RunFrom(x_hat, P_hat, x_hat, models, estimated_teammates, considered_teammates, stamp_ns);
}

EsikfUpdateResult EsikfUpdate::RunFrom(const SwarmState& x_hat, const Eigen::MatrixXd& P_hat,
                                       const SwarmState& x_start,
                                       const std::vector<MeasurementModel*>& models,
                                       const std::vector<int>* estimated_teammates,
                                       const std::vector<int>* considered_teammates,
                                       std::optional<int64_t> stamp_ns) const {
  const bool none_considered = considered_teammates == nullptr || considered_teammates->empty();
  if (none_considered && (estimated_teammates == nullptr ||
                          *estimated_teammates == x_hat.layout().teammate_ids())) {
    return RunAll(x_hat, P_hat, x_start, models, {}, stamp_ns);
  }
  EsikfUpdateResult result;
  result.state = x_hat;
  result.covariance = P_hat;
  const ErrorStateLayout& layout = x_hat.layout();
  // The blocks in the solve (estimated and considered) in layout order.
  std::vector<int> ids;
  std::vector<int> considered;
  result.status =
      SelectTeammates(layout, estimated_teammates, considered_teammates, &ids, &considered);
  if (!result.status.ok()) return result;
  if (P_hat.rows() != x_hat.Dim() || P_hat.cols() != x_hat.Dim() ||
      x_start.layout() != layout) {
    result.status = Status::InvalidArgument("EsikfUpdate: P_hat / x_start do not match x_hat");
    return result;
  }
  const std::vector<int> s_idx = SubsetIndices(layout, ids);
  const std::vector<int> o_idx = Complement(s_idx, x_hat.Dim());
  const Eigen::MatrixXd P_ss = Gather(P_hat, s_idx, s_idx);
  EsikfUpdateResult sub =
      RunAll(SubsetState(x_hat, ids), P_ss, SubsetState(x_start, ids), models, considered,
             stamp_ns);
  CopyRunStatistics(sub, &result);
  if (!sub.status.ok()) return result;

  // Schmidt-Kalman: x_o and P_oo unchanged, P_os updated (and P_ss from the
  // sub-update).
  const Clock::time_point t_cov = Clock::now();
  result.state.ego = sub.state.ego;
  for (int id : ids) result.state.teammate(id) = sub.state.teammate(id);
  const Eigen::MatrixXd P_os_plus = SchmidtKalmanCrossCovariance(
      SubsetState(x_hat, ids), sub.state, ids, Gather(P_hat, o_idx, s_idx), P_ss, sub.covariance);
  ScatterCovariance(s_idx, o_idx, sub.covariance, P_os_plus, &result.covariance);
  if (!considered.empty()) {
    RestoreConsideredCovariance(layout, considered, o_idx, P_hat, &result.covariance);
  }
  result.covariance_time_s += SecondsSince(t_cov);
  return result;
}

EsikfUpdateResult EsikfUpdate::RunAll(const SwarmState& x_hat,
                                      const Eigen::MatrixXd& P_hat,
                                      const SwarmState& x_start,
                                      const std::vector<MeasurementModel*>& models,
                                      const std::vector<int>& held,
                                      std::optional<int64_t> stamp_ns) const {
  const Clock::time_point t_start = Clock::now();
  EsikfUpdateResult result;
  result.state = x_hat;
  result.covariance = P_hat;
  const auto fail = [&](Status status) {
    result.status = std::move(status);
    result.total_time_s = SecondsSince(t_start);
    return result;
  };
  Eigen::MatrixXd cholesky;
  if (Status invalid = CheckRunInputs(options_, x_hat, P_hat, x_start, models, &cholesky);
      !invalid.ok()) {
    return fail(std::move(invalid));
  }

  SwarmState x = x_start;
  const auto hold = [&x_hat, &held](SwarmState* at) {
    for (int id : held) at->teammate(id) = x_hat.teammate(id);
  };
  hold(&x);
  UpdateProblem up(x_hat, std::move(cholesky), x);
  ParameterBlocks& blocks = up.blocks;

  const ceres::Solver::Options solver_options = GaussNewtonStepOptions(options_.linear_solver);
  for (int it = 0; it < options_.max_iterations; ++it) {
    if (Status status = Relinearize(models, x, stamp_ns, &up, &result.association_time_s);
        !status.ok()) {
      return fail(std::move(status));
    }
    result.num_residual_blocks = static_cast<int>(up.measurements.ids.size());

    const Clock::time_point t_solve = Clock::now();
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &up.problem, &summary);
    result.solve_time_s += SecondsSince(t_solve);
    if (!summary.IsSolutionUsable()) {
      return fail(Status::Internal("EsikfUpdate: Ceres failed: " + summary.message));
    }
    result.num_rejected_steps += summary.num_unsuccessful_steps;
    ++result.iterations;

    SwarmState x_next = blocks.Read(x);
    if (!held.empty()) {
      hold(&x_next);
      blocks.Write(x_next);
    }
    const Eigen::VectorXd dx = x_next.BoxMinus(x);
    x = x_next;
    if (summary.num_unsuccessful_steps > 0) break;  // Ceres refused the GN step
    if (StepIsSmall(dx, x.layout(), options_)) {
      result.converged = true;
      break;
    }
  }

  const Clock::time_point t_cov = Clock::now();
  blocks.Write(x);
  Eigen::MatrixXd P;
  if (Status status = PosteriorCovariance(up, x, models, &P); !status.ok()) {
    return fail(std::move(status));
  }
  result.covariance_time_s = SecondsSince(t_cov);
  result.state = std::move(x);
  result.covariance = std::move(P);
  result.total_time_s = SecondsSince(t_start);
  return result;
}

}  // namespace swarmlio::lio
