// The one-step Gauss-Newton solver options and the point-to-plane
// measurement model of the iterated update (esikf_update.h; docs/esikf.md).
#include <ceres/solver.h>

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "swarmlio/lio/esikf_update.h"

namespace swarmlio::lio {

// Undamped Gauss-Newton with Ceres's trust-region minimizer: one step per
// Solve, Levenberg-Marquardt with a radius of 1e16 so that the damping
// diag(J^T J) / radius is 1e-16 relative (docs/esikf.md).
ceres::Solver::Options GaussNewtonStepOptions(ceres::LinearSolverType linear_solver) {
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
  s.linear_solver_type = linear_solver;
  s.dense_linear_algebra_library_type = ceres::EIGEN;
  s.num_threads = 1;
  s.minimizer_progress_to_stdout = false;
  s.logging_type = ceres::SILENT;
  return s;
}

PlaneMeasurementModel::PlaneMeasurementModel(PlaneAssociationFn associate)
    : associate_(std::move(associate)), factor_(&correspondences_) {}

Status PlaneMeasurementModel::Linearize(const SwarmState& x, std::vector<ResidualTerm>* terms) {
  if (!associate_) return Status::InvalidArgument("no association callback");
  correspondences_.clear();
  SWARMLIO_RETURN_IF_ERROR(associate_(x, &correspondences_));
  if (correspondences_.empty()) return Status::Ok();
  // The N point rows enter Ceres as their 6-row information form at x
  // (PoseInformationFactor): the same Gauss-Newton step, a 6-row instead of
  // an N-row Jacobian block (docs/esikf.md "Compressed point rows").
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  factor_.AccumulateNormalEquations(x.ego, &A, &b);
  compressed_.Set(A, b, x.ego.q_G_b, x.ego.p_b_in_G);
  terms->push_back({&compressed_, {StateKey::Ego()}});
  return Status::Ok();
}

bool PlaneMeasurementModel::AddInformation(const SwarmState& x,
                                           Eigen::MatrixXd* information) const {
  Eigen::Matrix<double, 6, 6> HtH = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> Htz = Eigen::Matrix<double, 6, 1>::Zero();
  factor_.AccumulateNormalEquations(x.ego, &HtH, &Htz);
  static_assert(ErrorStateLayout::kRotation.offset == 0 && ErrorStateLayout::kPosition.offset == 3);
  information->topLeftCorner<6, 6>() += HtH;
  return true;
}

}  // namespace swarmlio::lio
