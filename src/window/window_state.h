// The state of the fixed-lag window smoother (src/window/window_smoother.h):
// its scans, teammate blocks and prior, shared by window_smoother.cc
// (adding states, marginalization) and window_solve.cc (the solve and the
// newest covariance). Internal to swarmlio_window.
#pragma once

#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "factors/imu_preintegration_factor.h"
#include "factors/marginalization_prior_factor.h"
#include "factors/point_to_plane_factor.h"
#include "factors/pose_information_factor.h"
#include "swarmlio/common/stopwatch.h"
#include "swarmlio/lio/imu_preintegration.h"
#include "swarmlio/window/marginalization.h"
#include "window_smoother.h"

namespace swarmlio::window {

using Clock = std::chrono::steady_clock;
using EgoParameters = std::array<double, EgoState::kAmbientSize>;
using TeammateParameters = std::array<double, GlobalExtrinsic::kAmbientSize>;
constexpr int kEgoDim = EgoState::kTangentSize;
constexpr int kTeammateDim = GlobalExtrinsic::kTangentSize;

// One scan state of the window.
struct WindowScan {
  int64_t stamp_ns = 0;
  EgoParameters ego{};
  std::vector<Eigen::Vector3d> points_in_b;
  std::vector<lio::ExcludedRegion> excluded;
  bool use_planes = false;  // enough points
  bool in_map = false;      // its points are in the map (it built the map, or was flushed)
  bool updated = false;     // its planes were in a successful solve
  std::unique_ptr<lio::ScanAssociator> associator;
  std::vector<PlaneCorrespondence> correspondences;  // of the last association
  PointToPlaneFactor planes{&correspondences};       // the point rows (normal equations)
  PoseInformationFactor compressed;                  // what Ceres and the marginalizer see
  lio::AssociationStats stats;
  std::unique_ptr<lio::ImuPreintegration> imu;  // from the previous state (none for the first)
  std::unique_ptr<ImuPreintegrationFactor> imu_factor;
  // The hooks' terms taken over with this scan, every ego key an EgoAt (Ego()
  // rewritten to this scan's stamp); they may name earlier states too.
  std::vector<lio::OwnedResidualTerm> observations;

  EgoState State() const { return EgoState::FromParameters(ego.data()); }
  // The plane information of a successful solve, linearized at the current value.
  bool HasPlaneInformation() const { return updated && !correspondences.empty(); }
  // Re-linearizes the compressed rows at the current value (same correspondences).
  void RefreshPlanes() {
    const EgoState x = State();
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    planes.AccumulateNormalEquations(x, &A, &b);
    compressed.Set(A, b, x.q_G_b, x.p_b_in_G);
  }
};

struct TeammateBlock {
  int id = 0;
  TeammateParameters x{};
};

// The window's one prior, over the oldest ego state and every teammate block
// (and any later state a marginalized term named): the first state's (from
// the filter's prediction), then each marginalization's; a new teammate's
// block is appended to it.
struct Prior {
  MarginalizationPrior system;  // H*, b*, the blocks and their linearization points
  std::unique_ptr<MarginalizationPriorFactor> factor;

  bool Touches(const double* block) const {
    const auto& b = system.parameter_blocks;
    return std::find(b.begin(), b.end(), block) != b.end();
  }
};

struct WindowSmoother::Impl {
  lio::WindowOptions options;
  lio::ImuPreintegrationOptions preintegration;
  lio::ProcessNoiseOptions process_noise;  // the propagator's (teammate random walks)
  lio::ScanAssociationOptions association;
  lio::EsikfUpdateOptions update;
  const lio::LocalMap* map = nullptr;
  const lio::ParallelFor* parallel = nullptr;  // the scans' association (null: one thread)
  EgoStateManifold ego_manifold;
  GlobalExtrinsicManifold teammate_manifold;
  MarginalizationPriorFactorOptions prior_options;
  std::unique_ptr<Marginalizer> marginalizer;
  std::deque<std::unique_ptr<WindowScan>> scans;
  std::vector<std::unique_ptr<TeammateBlock>> teammates;  // the newest prediction's layout order
  Prior prior;  // factor == nullptr only while the window is empty
  std::unique_ptr<lio::ImuPreintegration> interval;  // being integrated towards the next state
  bool interval_ok = false;
  WindowCounters counters;

  double* Teammate(int id) const {
    for (const auto& t : teammates) {
      if (t->id == id) return t->x.data();
    }
    return nullptr;
  }
  Status SetPrior(MarginalizationPrior system);
  // The prior N(current values, covariance) over `blocks`.
  Status SetGaussianPrior(const std::vector<double*>& blocks,
                          const std::vector<const ceres::Manifold*>& manifolds,
                          const Eigen::MatrixXd& covariance);
  // Appends an independent block N(current value, covariance) to the prior.
  Status ExtendPrior(double* block,
                     const ceres::Manifold* manifold,
                     const Eigen::MatrixXd& covariance);
  // The teammates' random walk over an interval (the propagator's process
  // noise, sum_dt2 = sum of the squared IMU steps) added to a prior's
  // teammate blocks, in information form.
  void AddTeammateRandomWalk(double sum_dt2, MarginalizationPrior* system) const;
  void Leave(WindowScan* scan, std::vector<LeavingScan>* leaving);
  Status Restart(WindowStateInput* input, std::vector<LeavingScan>* leaving);
  Status SyncTeammates(const SwarmState& x_pred, const Eigen::MatrixXd& P_pred);
  Status RemoveTeammate(int id);
  // Adds every kept term that names the leaving state s0 to the
  // marginalizer (window order: s0's own terms first) and their other
  // blocks to `kept`.
  Status AddTermsNaming(const WindowScan& s0, std::vector<double*>* kept);
  // After s0's marginalization: the terms that named it leave every scan;
  // s0's terms that did not move to the next scan.
  void DropTermsNaming(WindowScan* s0);
  Status MarginalizeOldest(std::vector<LeavingScan>* leaving);
  // Checks a term handed over with the scan at `stamp_ns` and rewrites its
  // Ego() keys to EgoAt(stamp_ns): every key must name a block the window
  // holds, with the cost's block size; the error names the model and key.
  Status AdoptTerm(int64_t stamp_ns, const char* model, lio::OwnedResidualTerm* term) const;
  Status TakeObservations(WindowStateInput* input, WindowScan* scan);
  Status AddState(WindowStateInput* input,
                  std::vector<LeavingScan>* leaving,
                  std::string* model_error);
  void ReintegrateImu();
  // Solve, step by step (window_solve.cc). The scans with point-to-plane
  // terms (`active`) and, of those, the ones re-associated at each
  // iteration (their associators reset: the map changed).
  void SelectPlaneScans(std::vector<WindowScan*>* active, std::vector<WindowScan*>* associated);
  // The parameter blocks and every residual block of the window; returns
  // the number of measurement blocks (planes, observations).
  int AddResidualBlocks(const std::vector<WindowScan*>& active, ceres::Problem* problem);
  // Re-associates `associated` at their current values and re-linearizes
  // the planes of every active scan; the first association error.
  Status Reassociate(const std::vector<WindowScan*>& associated,
                     const std::vector<WindowScan*>& active);
  // Every state's step from `start` (Values()) below the update's thresholds.
  bool StepIsSmall(const std::vector<double>& start) const;
  // The Gauss-Newton iterations with re-association.
  void Iterate(const std::vector<WindowScan*>& active,
               const std::vector<WindowScan*>& associated,
               ceres::Problem* problem,
               WindowSolveResult* result);
  // After the iterations: restores `before` on failure (or a non-finite
  // solution), re-linearizes the active planes, reports the newest scan's.
  void FinishIterations(const std::vector<double>& before,
                        const std::vector<WindowScan*>& active,
                        WindowSolveResult* result);
  Status NewestCovariance(Eigen::MatrixXd* P) const;
  void ReadState(SwarmState* x) const;
  std::vector<double> Values() const;
  void Restore(const std::vector<double>& values);
  // The scan whose state is at `stamp_ns`, nullptr if none in the window.
  // Newest first: the scan being added is found even if (against the
  // odometry's strictly increasing scan ends) an older state had its stamp.
  WindowScan* ScanAt(int64_t stamp_ns) const {
    for (auto it = scans.rbegin(); it != scans.rend(); ++it) {
      if ((*it)->stamp_ns == stamp_ns) return it->get();
    }
    return nullptr;
  }
  // The parameter block a key of a kept term names (EgoAt(t): the window
  // state at t; Extrinsic(id): the teammate block); nullptr when the window
  // does not hold it (and for Ego(), which no kept term holds).
  double* BlockOf(const lio::StateKey& key) const {
    switch (key.kind()) {
      case lio::StateKey::Kind::kEgoAt: {
        WindowScan* s = ScanAt(key.stamp_ns());
        return s == nullptr ? nullptr : s->ego.data();
      }
      case lio::StateKey::Kind::kTeammateExtrinsic:
        return Teammate(key.teammate_id());
      case lio::StateKey::Kind::kEgo:
        break;
    }
    return nullptr;
  }
  const ceres::Manifold* ManifoldOf(const lio::StateKey& key) const {
    return key.is_ego() ? static_cast<const ceres::Manifold*>(&ego_manifold) : &teammate_manifold;
  }
  // A kept term's parameter blocks and manifolds, in its key order.
  void BlocksOf(const lio::OwnedResidualTerm& term,
                std::vector<double*>* blocks,
                std::vector<const ceres::Manifold*>* manifolds) const {
    for (const lio::StateKey& key : term.blocks) {
      blocks->push_back(BlockOf(key));
      if (manifolds != nullptr) manifolds->push_back(ManifoldOf(key));
    }
  }
};

}  // namespace swarmlio::window
