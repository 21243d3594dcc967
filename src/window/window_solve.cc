// WindowSmoother::Solve and the newest state's marginal covariance
// (docs/window.md, "The window", steps 3 and 4).
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "factors/term_linearizer.h"
#include "window_smoother.h"
#include "window_state.h"

namespace swarmlio::window {
namespace {

ceres::LinearSolverType ToCeres(lio::WindowLinearSolver solver) {
  switch (solver) {
    case lio::WindowLinearSolver::kDenseQr:
      return ceres::DENSE_QR;
    case lio::WindowLinearSolver::kDenseSchur:
      return ceres::DENSE_SCHUR;
    case lio::WindowLinearSolver::kSparseNormalCholesky:
      return ceres::SPARSE_NORMAL_CHOLESKY;
    case lio::WindowLinearSolver::kDenseNormalCholesky:
      break;
  }
  return ceres::DENSE_NORMAL_CHOLESKY;
}

// Adds J^T J of one residual block at the blocks' current values (tangent
// Jacobians, factors/term_linearizer.h) to H at the blocks' offsets.
bool AddBlockInformation(const ceres::CostFunction& cost,
                         const std::vector<double*>& blocks,
                         const std::vector<const ceres::Manifold*>& manifolds,
                         const std::vector<int>& offsets,
                         Eigen::MatrixXd* H) {
  const size_t nb = blocks.size();
  Eigen::VectorXd residuals;
  std::vector<Eigen::MatrixXd> tangent;
  if (!LinearizeTerm(cost, blocks.data(), manifolds, &residuals, &tangent).ok()) return false;
  for (size_t a = 0; a < nb; ++a) {
    for (size_t b = 0; b < nb; ++b) {
      H->block(offsets[a], offsets[b], tangent[a].cols(), tangent[b].cols()) +=
          tangent[a].transpose() * tangent[b];
    }
  }
  return true;
}

}  // namespace

void WindowSmoother::Impl::ReintegrateImu() {
  for (size_t i = 1; i < scans.size(); ++i) {
    WindowScan& s = *scans[i];
    const EgoState previous = scans[i - 1]->State();
    const PreintegratedImu& pre = s.imu->preintegrated();
    if ((previous.gyro_bias - pre.gyro_bias_lin).norm() <= options.reintegrate_gyro_bias_rad_s &&
        (previous.accel_bias - pre.accel_bias_lin).norm() <= options.reintegrate_accel_bias_m_s2) {
      continue;
    }
    s.imu->Reintegrate(previous.gyro_bias, previous.accel_bias);
    std::unique_ptr<ImuPreintegrationFactor> factor;
    if (ImuPreintegrationFactor::Create(s.imu->preintegrated(), &factor).ok()) {
      s.imu_factor = std::move(factor);
      ++counters.reintegrations;
    }
  }
}

std::vector<double> WindowSmoother::Impl::Values() const {
  std::vector<double> v;
  for (const auto& s : scans) v.insert(v.end(), s->ego.begin(), s->ego.end());
  for (const auto& t : teammates) v.insert(v.end(), t->x.begin(), t->x.end());
  return v;
}

void WindowSmoother::Impl::Restore(const std::vector<double>& values) {
  auto it = values.begin();
  for (auto& s : scans) {
    std::copy(it, it + EgoState::kAmbientSize, s->ego.begin());
    it += EgoState::kAmbientSize;
  }
  for (auto& t : teammates) {
    std::copy(it, it + GlobalExtrinsic::kAmbientSize, t->x.begin());
    it += GlobalExtrinsic::kAmbientSize;
  }
}

void WindowSmoother::Impl::ReadState(SwarmState* x) const {
  *x = SwarmState();
  x->ego = scans.back()->State();
  for (const auto& t : teammates)
    x->AddTeammate(t->id, GlobalExtrinsic::FromParameters(t->x.data()));
}

Status WindowSmoother::Impl::NewestCovariance(Eigen::MatrixXd* P) const {
  const int n = static_cast<int>(scans.size());
  const int dim = kEgoDim * n + kTeammateDim * static_cast<int>(teammates.size());
  std::unordered_map<const double*, int> offsets;
  for (int i = 0; i < n; ++i) offsets[scans[static_cast<size_t>(i)]->ego.data()] = kEgoDim * i;
  for (size_t j = 0; j < teammates.size(); ++j) {
    offsets[teammates[j]->x.data()] = kEgoDim * n + kTeammateDim * static_cast<int>(j);
  }
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(dim, dim);
  const auto add = [&](const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                       const std::vector<const ceres::Manifold*>& manifolds) {
    std::vector<int> o;
    for (double* b : blocks) o.push_back(offsets.at(b));
    return AddBlockInformation(cost, blocks, manifolds, o, &H);
  };
  bool ok = true;
  if (prior.factor != nullptr) {
    ok = add(*prior.factor, prior.system.parameter_blocks, prior.system.manifolds);
  }
  for (int i = 0; i < n; ++i) {
    const WindowScan& s = *scans[static_cast<size_t>(i)];
    double* ego = const_cast<double*>(s.ego.data());
    if (i > 0) {
      double* previous = scans[static_cast<size_t>(i - 1)]->ego.data();
      ok = ok && add(*s.imu_factor, {previous, ego}, {&ego_manifold, &ego_manifold});
    }
    if (s.HasPlaneInformation()) ok = ok && add(s.compressed, {ego}, {&ego_manifold});
    for (const lio::OwnedResidualTerm& term : s.observations) {
      std::vector<double*> blocks;
      std::vector<const ceres::Manifold*> manifolds;
      BlocksOf(term, &blocks, &manifolds);
      ok = ok && add(*term.cost, blocks, manifolds);
    }
  }
  if (!ok) return Status::Internal("window: Jacobian evaluation failed (covariance)");
  const Eigen::LLT<Eigen::MatrixXd> llt(H);
  if (llt.info() != Eigen::Success) {
    return Status::Internal("window: information matrix is not positive definite");
  }
  // The newest ego block and the teammate blocks: the trailing columns.
  const int first = kEgoDim * (n - 1);
  const int m = dim - first;
  const Eigen::MatrixXd E = Eigen::MatrixXd::Identity(dim, dim).rightCols(m);
  Eigen::MatrixXd cov = llt.solve(E).bottomRows(m);
  *P = 0.5 * (cov + cov.transpose());
  return Status::Ok();
}

void WindowSmoother::Impl::SelectPlaneScans(std::vector<WindowScan*>* active,
                                            std::vector<WindowScan*>* associated) {
  if (map->empty()) return;
  for (auto& s : scans) {
    if (!s->use_planes || s->in_map) continue;
    active->push_back(s.get());
    // The older scans keep their correspondences (re-linearized) unless
    // every scan is re-associated (window.reassociate_all_scans).
    if (options.reassociate_all_scans || !s->updated || s.get() == scans.back().get()) {
      s->associator->Reset(&s->points_in_b);  // the map changed since the last solve
      associated->push_back(s.get());
    }
  }
}

int WindowSmoother::Impl::AddResidualBlocks(const std::vector<WindowScan*>& active,
                                            ceres::Problem* problem) {
  for (auto& s : scans) {
    problem->AddParameterBlock(s->ego.data(), EgoState::kAmbientSize, &ego_manifold);
  }
  for (auto& t : teammates) {
    problem->AddParameterBlock(t->x.data(), GlobalExtrinsic::kAmbientSize, &teammate_manifold);
  }
  if (prior.factor != nullptr) {
    problem->AddResidualBlock(prior.factor.get(), nullptr, prior.system.parameter_blocks);
  }
  for (size_t i = 1; i < scans.size(); ++i) {
    problem->AddResidualBlock(scans[i]->imu_factor.get(), nullptr, scans[i - 1]->ego.data(),
                              scans[i]->ego.data());
  }
  for (WindowScan* s : active) problem->AddResidualBlock(&s->compressed, nullptr, s->ego.data());
  int num_measurement_blocks = 0;
  for (auto& s : scans) {
    for (const lio::OwnedResidualTerm& term : s->observations) {
      std::vector<double*> blocks;
      BlocksOf(term, &blocks, nullptr);
      problem->AddResidualBlock(term.cost.get(), nullptr, blocks);
      ++num_measurement_blocks;
    }
  }
  num_measurement_blocks += static_cast<int>(active.size());
  return num_measurement_blocks;
}

Status WindowSmoother::Impl::Reassociate(const std::vector<WindowScan*>& associated,
                                         const std::vector<WindowScan*>& active) {
  Status status;
  for (WindowScan* s : associated) {
    SwarmState at;
    at.ego = s->State();
    status = s->associator->Associate(at, &s->correspondences);
    if (!status.ok()) break;
    s->stats = s->associator->stats();
  }
  for (WindowScan* s : active) s->RefreshPlanes();
  return status;
}

bool WindowSmoother::Impl::StepIsSmall(const std::vector<double>& start) const {
  // Converged when every state's step is below the filter's thresholds.
  bool small = true;
  size_t offset = 0;
  for (const auto& s : scans) {
    const EgoState old_x = EgoState::FromParameters(start.data() + offset);
    const auto dx = s->State().BoxMinus(old_x);
    small = small && dx.segment<3>(ErrorStateLayout::kRotation.offset).norm() <
                         update.convergence_rotation_rad;
    small = small && dx.segment<3>(ErrorStateLayout::kPosition.offset).norm() <
                         update.convergence_translation_m;
    offset += EgoState::kAmbientSize;
  }
  for (const auto& t : teammates) {
    const GlobalExtrinsic old_T = GlobalExtrinsic::FromParameters(start.data() + offset);
    const auto dx = GlobalExtrinsic::FromParameters(t->x.data()).BoxMinus(old_T);
    small = small && dx.head<3>().norm() < update.convergence_rotation_rad &&
            dx.tail<3>().norm() < update.convergence_translation_m;
    offset += GlobalExtrinsic::kAmbientSize;
  }
  return small;
}

void WindowSmoother::Impl::Iterate(const std::vector<WindowScan*>& active,
                                   const std::vector<WindowScan*>& associated,
                                   ceres::Problem* problem,
                                   WindowSolveResult* result) {
  ceres::Solver::Options solver_options =
      lio::GaussNewtonStepOptions(ToCeres(options.linear_solver));
  solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  for (int it = 0; it < options.max_iterations; ++it) {
    const Clock::time_point t_assoc = Clock::now();
    result->status = Reassociate(associated, active);
    result->association_s += SecondsSince(t_assoc);
    if (!result->status.ok()) break;
    const std::vector<double> start = Values();
    const Clock::time_point t_solve = Clock::now();
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, problem, &summary);
    result->solve_s += SecondsSince(t_solve);
    if (!summary.IsSolutionUsable()) {
      result->status = Status::Internal("window: Ceres failed: " + summary.message);
      break;
    }
    ++result->iterations;
    result->num_rejected_steps += summary.num_unsuccessful_steps;
    if (summary.num_unsuccessful_steps > 0) break;
    if (StepIsSmall(start)) {
      result->converged = true;
      break;
    }
  }
}

void WindowSmoother::Impl::FinishIterations(const std::vector<double>& before,
                                            const std::vector<WindowScan*>& active,
                                            WindowSolveResult* result) {
  const std::vector<double> after = Values();
  const bool finite =
      std::all_of(after.begin(), after.end(), [](double v) { return std::isfinite(v); });
  if (result->status.ok() && !finite) {
    result->status = Status::Internal("window: non-finite solution");
  }
  if (!result->status.ok()) Restore(before);
  for (WindowScan* s : active) {
    if (result->status.ok()) s->updated = true;
    s->RefreshPlanes();  // at the final (or restored) value, for covariance and marginalization
  }
  WindowScan& newest = *scans.back();
  const bool newest_active = std::find(active.begin(), active.end(), &newest) != active.end();
  if (newest_active) {
    result->updated = result->status.ok();
    result->num_correspondences = static_cast<int>(newest.correspondences.size());
    result->newest_stats = newest.stats;
  }
}

WindowSolveResult WindowSmoother::Solve() {
  Impl& im = *impl_;
  WindowSolveResult result;
  if (im.scans.empty()) {
    result.status = Status::FailedPrecondition("window: no state");
    return result;
  }
  const Clock::time_point t_build = Clock::now();
  im.ReintegrateImu();
  std::vector<WindowScan*> active;      // scans with point-to-plane terms
  std::vector<WindowScan*> associated;  // of those, the ones re-associated at each iteration
  im.SelectPlaneScans(&active, &associated);
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  result.num_residual_blocks = im.AddResidualBlocks(active, &problem);
  result.build_s = SecondsSince(t_build);

  if (!active.empty()) {
    const std::vector<double> before = im.Values();
    im.Iterate(active, associated, &problem, &result);
    im.FinishIterations(before, active, &result);
  }

  const Clock::time_point t_cov = Clock::now();
  im.ReadState(&result.state);
  const Status covariance = im.NewestCovariance(&result.covariance);
  if (!covariance.ok()) {
    result.updated = false;
    if (result.status.ok()) result.status = covariance;
  }
  result.covariance_s = SecondsSince(t_cov);
  return result;
}

}  // namespace swarmlio::window
