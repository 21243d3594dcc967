// EsikfUpdate: the iterated error-state Kalman update of one LiDAR scan
// (paper Sec. III-D, FAST-LIO2's IEKF) written as undamped Gauss-Newton on a
// Ceres problem with the ego / teammate parameter blocks, their manifolds, a
// PriorFactor (x_hat, P_hat) and the residual blocks of any number of
// measurement models (measurement_model.h): point-to-plane, active and
// passive mutual observations, ... The formulation, the Ceres configuration,
// the equivalence with the IEKF equations and the measured cost are in
// docs/esikf.md.
//
// Each outer iteration i: every model re-linearizes at x_i (re-association
// included), then one Gauss-Newton step x_{i+1} = x_i (+) dx_i; stop when
// every rotation step is below convergence_rotation_rad and every translation
// step below convergence_translation_m, or after max_iterations. The
// posterior covariance is (J^T J)^-1 at the final estimate, J the tangent
// Jacobian of all residual blocks (prior included), placed in
// ErrorStateLayout order by the blocks each term names.
//
// Teammate subset (docs/esikf.md "Blocks left out"): an update may estimate
// only some teammate blocks (those observed in this scan). The others keep
// their mean and marginal covariance; their cross-covariance with the
// estimated blocks becomes P_os P_ss^-1 P_ss^+ (the Schmidt-Kalman
// "consider" update: exact covariance of an estimator that does not correct
// them), so the cost grows with the teammates observed, not with the swarm.
//
// Considered teammates (the degeneracy policy consider_extrinsics,
// docs/esikf.md "Considered blocks"): blocks the residuals name but the
// update does not correct. They enter the solve with their covariance, so
// their uncertainty reaches the innovation and the gain of the estimated
// blocks (K_s = (P_ss H_s^T + P_sc H_c^T) S^-1), but every iteration's step
// for them is discarded (the residuals are linearized at their prior mean);
// then their marginal covariance and their cross-covariance with every block
// not estimated are restored (iterated Schmidt-Kalman).
#pragma once

#include <ceres/solver.h>
#include <ceres/types.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "factors/point_to_plane_factor.h"
#include "factors/pose_information_factor.h"
#include "swarmlio/lio/measurement_model.h"
#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

struct EsikfUpdateOptions {
  /// Outer iterations (re-association + Gauss-Newton step). FAST-LIO2 uses 4.
  int max_iterations = 4;
  /// Converged when every rotation step (ego and teammates) is below this [rad]
  /// (default 0.01 deg, Swarm-LIO's threshold) ...
  double convergence_rotation_rad = 0.01 * M_PI / 180.0;
  /// ... and every translation step (p_b_in_G, p_Gj_in_Gi) below this [m].
  double convergence_translation_m = 1.5e-4;
  /// DENSE_NORMAL_CHOLESKY (default, fastest for ~18-40 columns) or DENSE_QR.
  ceres::LinearSolverType linear_solver = ceres::DENSE_NORMAL_CHOLESKY;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("max_iterations", max_iterations,
      FieldSpec::InRange(1.0, 100.0, "", "outer iterations (re-association + Gauss-Newton step)"));
    v("convergence_rotation_rad", convergence_rotation_rad,
      FieldSpec::Positive("rad", "converged when every rotation step is below this"));
    v("convergence_translation_m", convergence_translation_m,
      FieldSpec::Positive("m", "converged when every translation step is below this"));
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const;
};

/// Ceres options for exactly one undamped Gauss-Newton step per Solve: the
/// trust-region minimizer with Levenberg-Marquardt at a radius of 1e16, no
/// stopping tolerance, one thread, silent (docs/esikf.md, "Gauss-Newton
/// configuration of Ceres"). The update's and the window smoother's solver.
ceres::Solver::Options GaussNewtonStepOptions(ceres::LinearSolverType linear_solver);

/// Fills `out` (cleared by the caller) with the plane correspondences of the
/// scan at the estimate x. A non-ok Status aborts the update.
using PlaneAssociationFn =
    std::function<Status(const SwarmState& x, std::vector<PlaneCorrespondence>* out)>;

struct EsikfUpdateResult {
  Status status;                    // non-ok: bad input/options or failed association
  SwarmState state;                 // posterior estimate (x_hat on failure)
  Eigen::MatrixXd covariance;       // posterior P, Dim x Dim (P_hat on failure)
  int iterations = 0;               // outer iterations run
  bool converged = false;           // step thresholds met before max_iterations
  int num_correspondences = 0;      // at the last association (PlaneMeasurementModel)
  int num_residual_blocks = 0;      // measurement residual blocks at the last iteration
  int num_rejected_steps = 0;       // steps Ceres refused because the cost rose
  double association_time_s = 0.0;  // total time in the callback [s]
  double solve_time_s = 0.0;        // total time in ceres::Solve [s]
  double covariance_time_s = 0.0;   // posterior covariance [s]
  double total_time_s = 0.0;        // whole Run [s]
};

class EsikfUpdate {
 public:
  explicit EsikfUpdate(EsikfUpdateOptions options = {});

  /// Iterated update starting from x_hat. P_hat is Dim x Dim, symmetric
  /// positive definite, in ErrorStateLayout order of x_hat.
  EsikfUpdateResult Run(const SwarmState& x_hat,
                        const Eigen::MatrixXd& P_hat,
                        const PlaneAssociationFn& associate) const;

  /// As Run, but the iteration starts at x_start (same layout as x_hat)
  /// instead of x_hat; the prior stays centred at x_hat.
  EsikfUpdateResult RunFrom(const SwarmState& x_hat,
                            const Eigen::MatrixXd& P_hat,
                            const SwarmState& x_start,
                            const PlaneAssociationFn& associate) const;

  /// The general form: prior + the residual blocks of `models`, each
  /// re-linearized at every iteration. `estimated_teammates`: the teammate
  /// ids whose blocks this update estimates (nullptr: all in x_hat's layout;
  /// ids absent from the layout are an error); see the file comment.
  /// `considered_teammates`: ids (in the layout, none also estimated) whose
  /// blocks the residuals may name but the update does not correct (file
  /// comment). With estimated_teammates nullptr, every teammate not
  /// considered is estimated. `stamp_ns`: the time of x_hat (the scan end
  /// [ns]); the models' terms may name the ego state as StateKey::Ego() or
  /// EgoAt(stamp_ns), any other EgoAt is InvalidArgument (the filter holds
  /// one state; without a stamp every EgoAt is).
  EsikfUpdateResult Run(const SwarmState& x_hat,
                        const Eigen::MatrixXd& P_hat,
                        const std::vector<MeasurementModel*>& models,
                        const std::vector<int>* estimated_teammates = nullptr,
                        const std::vector<int>* considered_teammates = nullptr,
                        std::optional<int64_t> stamp_ns = std::nullopt) const;
  EsikfUpdateResult RunFrom(const SwarmState& x_hat,
                            const Eigen::MatrixXd& P_hat,
                            const SwarmState& x_start,
                            const std::vector<MeasurementModel*>& models,
                            const std::vector<int>* estimated_teammates = nullptr,
                            const std::vector<int>* considered_teammates = nullptr,
                            std::optional<int64_t> stamp_ns = std::nullopt) const;

  const EsikfUpdateOptions& options() const { return options_; }

 private:
  // All blocks of x_hat in the solve; the teammates in `held` (considered)
  // stay at x_hat: every iteration's step for them is discarded, so the
  // residuals are linearized there and the others get the iterated
  // Schmidt-Kalman step.
  EsikfUpdateResult RunAll(const SwarmState& x_hat, const Eigen::MatrixXd& P_hat,
                           const SwarmState& x_start,
                           const std::vector<MeasurementModel*>& models,
                           const std::vector<int>& held = {},
                           std::optional<int64_t> stamp_ns = std::nullopt) const;
  EsikfUpdateOptions options_;
};

/// The point-to-plane model: at every iteration the callback re-associates
/// the scan at the estimate; one PointToPlaneFactor residual block (ego).
class PlaneMeasurementModel final : public MeasurementModel {
 public:
  explicit PlaneMeasurementModel(PlaneAssociationFn associate);
  const char* name() const override { return "point_to_plane"; }
  Status Linearize(const SwarmState& x, std::vector<ResidualTerm>* terms) override;
  /// H^T H of the point rows (6x6 over rotation and position, closed form).
  bool AddInformation(const SwarmState& x, Eigen::MatrixXd* information) const override;
  const std::vector<PlaneCorrespondence>& correspondences() const { return correspondences_; }

 private:
  PlaneAssociationFn associate_;
  std::vector<PlaneCorrespondence> correspondences_;
  PointToPlaneFactor factor_;         // the point rows (normal equations, posterior)
  PoseInformationFactor compressed_;  // what the Ceres problem holds (6 rows)
};

}  // namespace swarmlio::lio
