// The back end of lio::Odometry (`odometry.estimator: filter | window`) and
// the options of the fixed-lag window smoother (`odometry.window:`), issue
// #12; docs/window.md describes the window, its factors and how to choose K.
#pragma once

#include <array>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/window/marginalization.h"

namespace swarmlio::lio {

/// Which back end updates the state at every scan.
enum class EstimatorKind {
  kFilter,  // iterated ESIKF update of the newest state (docs/esikf.md)
  kWindow,  // fixed-lag smoother over the last K scan states (docs/window.md)
};

/// Ceres linear solver of the window's Gauss-Newton steps.
enum class WindowLinearSolver {
  kDenseNormalCholesky,
  kDenseQr,
  kDenseSchur,
  kSparseNormalCholesky,  // SuiteSparse (CHOLMOD)
};

}  // namespace swarmlio::lio

namespace swarmlio::config {
template <>
struct EnumTraits<lio::EstimatorKind> {
  static constexpr std::array<std::pair<lio::EstimatorKind, const char*>, 2> kNames{{
      {lio::EstimatorKind::kFilter, "filter"},
      {lio::EstimatorKind::kWindow, "window"},
  }};
};
template <>
struct EnumTraits<lio::WindowLinearSolver> {
  static constexpr std::array<std::pair<lio::WindowLinearSolver, const char*>, 4> kNames{{
      {lio::WindowLinearSolver::kDenseNormalCholesky, "dense_normal_cholesky"},
      {lio::WindowLinearSolver::kDenseQr, "dense_qr"},
      {lio::WindowLinearSolver::kDenseSchur, "dense_schur"},
      {lio::WindowLinearSolver::kSparseNormalCholesky, "sparse_normal_cholesky"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::lio {

struct WindowOptions {
  /// K: scan states kept in the window [scans]. With K = 1 the window is the
  /// filter (docs/window.md, "K = 1").
  int size = 5;
  /// Outer iterations per scan (re-association of every scan in the window
  /// + one Gauss-Newton step) [-]. The step thresholds are the filter's
  /// (update.convergence_rotation_rad, update.convergence_translation_m),
  /// applied to every state of the window.
  int max_iterations = 4;
  /// Re-associate every scan of the window against the map at each outer
  /// iteration (true), or only the newest scan (false): the older ones keep
  /// the correspondences of their last solve, re-linearized at the current
  /// estimate (docs/window.md, "Re-association").
  bool reassociate_all_scans = true;
  /// Linear solver of the Gauss-Newton step. DENSE_SCHUR was the fastest
  /// at K = 5 and 10 (docs/window.md, "Solver").
  WindowLinearSolver linear_solver = WindowLinearSolver::kDenseSchur;
  /// 1-sigma of g_k+1 - g_k in the IMU factor (gravity is constant; a floor
  /// keeps the factor's covariance positive definite) [m/s^2]. The filter
  /// keeps g exactly constant between updates: with K = 1, 1e-4 moved the
  /// window 2.4e-5 m / 1e-3 deg off the filter, 1e-5 2e-8 m / 3e-7 deg
  /// (docs/window.md, "K = 1").
  double gravity_stddev_floor_m_s2 = 1e-5;
  /// An IMU factor is preintegrated again at the current biases when its
  /// first state's gyro bias moved this far from the biases it was
  /// integrated with [rad/s] ...
  double reintegrate_gyro_bias_rad_s = 0.005;
  /// ... or its accelerometer bias this far [m/s^2].
  double reintegrate_accel_bias_m_s2 = 0.05;
  /// Schur complement of the states that leave the window.
  window::MarginalizationOptions marginalization;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("size", size, FieldSpec::InRange(1.0, 100.0, "scans", "K: scan states in the window"));
    config::VisitExperimental(v, [&](auto& x) {
      x("max_iterations", max_iterations,
        FieldSpec::InRange(1.0, 100.0, "", "outer iterations (re-association + Gauss-Newton step)"));
      x("reassociate_all_scans", reassociate_all_scans,
        FieldSpec::Doc("re-associate every scan of the window at each iteration (false: only "
                       "the newest; the others keep their correspondences)"));
      x("linear_solver", linear_solver,
        FieldSpec::Doc("Ceres linear solver of the Gauss-Newton step"));
      x("gravity_stddev_floor_m_s2", gravity_stddev_floor_m_s2,
        FieldSpec::Positive("m/s^2", "1-sigma of the gravity change between two window states")
            .WithMax(1.0));
      x("reintegrate_gyro_bias_rad_s", reintegrate_gyro_bias_rad_s,
        FieldSpec::Positive("rad/s", "preintegrate again when the gyro bias moved this far"));
      x("reintegrate_accel_bias_m_s2", reintegrate_accel_bias_m_s2,
        FieldSpec::Positive("m/s^2", "preintegrate again when the accel bias moved this far"));
      x("marginalization", marginalization);
    });
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

}  // namespace swarmlio::lio
