// WindowSmoother: the fixed-lag window back end of lio::Odometry (issue #12,
// docs/window.md). Internal to swarmlio_window: the odometry owns it, the map
// and the propagator, and drives it per scan.
//
// State: the last K scan states (ego blocks, EgoStateManifold) and one
// T_Gi_Gj block per teammate (GlobalExtrinsicManifold, shared by every scan
// of the window and kept through marginalization). Residual blocks:
//   - priors: the first state's prior from the filter's prediction and
//     covariance (information form), then the marginalization priors
//     (MarginalizationPriorFactor) of the states that left;
//   - one ImuPreintegrationFactor between consecutive states, preintegrated
//     from the IMU samples the propagator consumed (same discrete model);
//   - the point-to-plane terms of every scan in the window, re-associated
//     against the map at each outer iteration and handed to Ceres in
//     information form (PoseInformationFactor, as the filter does);
//   - the scan-stage hooks' residual terms (observations; any term naming
//     window states by lio::StateKey::EgoAt), taken over with the newest scan
//     (Ego() rewritten to EgoAt(its stamp)) and kept until the first state
//     they name is marginalized.
// Per scan: AddState (the new state; the oldest beyond K is marginalized
// and handed back for the map), then Solve (undamped Gauss-Newton, one Ceres
// step per outer iteration, like lio::EsikfUpdate), which returns the newest
// state and its marginal covariance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/esikf_update.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/measurement_model.h"
#include "swarmlio/lio/scan_association.h"
#include "swarmlio/lio/scan_stages.h"
#include "swarmlio/lio/window_options.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::window {

/// A scan that left the window (or, at the end of a log, was flushed), with
/// its final estimate, for the map.
struct LeavingScan {
  EgoState state;
  std::vector<Eigen::Vector3d> points_in_b;  // undistorted, body frame at the scan end
  std::vector<lio::ExcludedRegion> excluded;
  bool insert = false;       // updated by a solve and not in the map yet
  std::vector<int> matched;  // points matched to a map plane at its last association
};

/// The newest scan state.
struct WindowStateInput {
  int64_t stamp_ns = 0;    // the state time (scan end)
  SwarmState x_pred;       // the propagated prediction, teammate blocks included
  Eigen::MatrixXd P_pred;  // its covariance (prior of a (re)started window, new teammates)
  std::vector<Eigen::Vector3d> points_in_b;   // undistorted scan
  bool use_planes = false;                    // enough points for point-to-plane terms
  std::vector<lio::ExcludedRegion> excluded;  // kept out of the map
  /// The hooks' models of this scan: their terms are taken over
  /// (lio::MeasurementModel::ReleaseTerms) and stay with the scan's state.
  std::vector<lio::MeasurementModel*> models;
  /// Teammates the filter would consider (lio::UpdateRequest): the window holds
  /// them at x_pred in this scan's terms (docs/window.md).
  std::vector<int> considered_teammates;
};

struct WindowSolveResult {
  Status status;               // non-ok: the states keep their values before the solve
  SwarmState state;            // newest state, teammates in x_pred's layout order
  Eigen::MatrixXd covariance;  // its marginal covariance (same layout)
  bool updated = false;        // the newest scan's point-to-plane terms were in a successful solve
  int iterations = 0;
  bool converged = false;
  int num_rejected_steps = 0;
  int num_correspondences = 0;  // newest scan, last iteration
  int num_residual_blocks = 0;  // measurement blocks (planes, observations) in the window
  lio::AssociationStats newest_stats;
  double build_s = 0.0;        // IMU re-integration, problem construction [s]
  double association_s = 0.0;  // every scan, every iteration [s]
  double solve_s = 0.0;        // ceres::Solve [s]
  double covariance_s = 0.0;   // marginal covariance of the newest state [s]
};

struct WindowCounters {
  int64_t restarts = 0;        // the window restarted from the propagator (IMU gap, bad factor)
  int64_t reintegrations = 0;  // IMU factors preintegrated again at new biases
  int64_t marginalizations = 0;
};

class WindowSmoother {
 public:
  /// InvalidArgument when the options do not validate. `map` (and
  /// `parallel`, the scans' association threads; null: one) must outlive
  /// the smoother; the odometry inserts the scans that leave.
  static Status Create(const lio::WindowOptions& options,
                       const lio::ImuPropagatorOptions& propagation,
                       const lio::ScanAssociationOptions& association,
                       const lio::EsikfUpdateOptions& update,
                       const lio::LocalMap* map,
                       std::unique_ptr<WindowSmoother>* smoother,
                       const lio::ParallelFor* parallel = nullptr);
  ~WindowSmoother();

  /// The IMU interval from the newest state to the next one, fed with
  /// exactly what the propagator consumes: StartInterval at the newest
  /// state's time with the propagator's last sample, AddImu per sample,
  /// IntegrateTo the scan end. Anything the preintegration refuses (a gap)
  /// breaks the interval: the next state restarts the window.
  void StartInterval(int64_t stamp_ns,
                     const ImuSample& last_sample,
                     double acceleration_to_m_s2,
                     const EgoState& newest);
  void AddImu(const ImuSample& sample);
  void IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample);
  void BreakInterval();

  /// Adds the newest state; the states beyond K are marginalized and
  /// appended to `*leaving` (oldest first). `*marginalize_s`: time spent [s].
  /// A hook model whose terms cannot be kept is left out, and so is a term
  /// that does not match its state blocks or names a state the window does
  /// not hold (a marginalized or never-added EgoAt stamp, an absent
  /// teammate); `*model_error` names the last such model and key ("" if
  /// none). An error (a prior that is not positive definite, a failed
  /// marginalization) empties the window into `*leaving`; the next state
  /// restarts it.
  Status AddState(WindowStateInput input,
                  std::vector<LeavingScan>* leaving,
                  double* marginalize_s,
                  std::string* model_error);
  /// The map was empty: the newest scan was inserted at its prediction and
  /// gets no point-to-plane terms (it built the map).
  void MarkNewestInMap();
  /// Solves the window (Gauss-Newton with re-association), or only computes
  /// the newest covariance when no scan can be associated yet.
  WindowSolveResult Solve();
  /// Every scan of the window not in the map yet, at its current estimate
  /// (end of a log); they count as in the map from now on.
  void TakeScansForMap(std::vector<LeavingScan>* scans);

  int size() const;
  const WindowCounters& counters() const;

 private:
  struct Impl;
  WindowSmoother();
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::window
