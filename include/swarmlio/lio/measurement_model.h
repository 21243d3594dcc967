// MeasurementModel: one kind of measurement in the iterated update
// (EsikfUpdate, docs/esikf.md "Measurement models"). The update calls
// Linearize at every outer iteration with the current estimate; the model
// re-associates if it needs to (point-to-plane re-finds its planes) and hands
// back its residual blocks: Ceres cost functions it owns, each with the state
// blocks it depends on. The update removes the previous iteration's blocks
// and adds the new ones, so a model may change the number and shape of its
// residuals from one iteration to the next.
//
// Conventions of a residual block: the residual is whitened (|r|^2 is the
// Mahalanobis distance of the measurement), its parameter blocks are ego
// states (EgoState ambient, 19) and/or teammate blocks (GlobalExtrinsic
// ambient, 7), named by StateKey (state_key.h) in the order of `blocks`:
// StateKey::Ego() for the state of the scan being updated, EgoAt(t) for the
// ego state at another scan end the back end holds, Extrinsic(id) for a
// teammate. The posterior covariance is formed from the tangent Jacobians of
// all blocks, so a model need not provide anything else.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include <memory>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/state_key.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

/// One residual block a model contributes at one iteration.
struct ResidualTerm {
  const ceres::CostFunction* cost = nullptr;  // owned by the model, valid until its next Linearize
  /// State blocks in the cost's parameter order.
  std::vector<StateKey> blocks;
};

/// A residual block handed over for good, to a back end that keeps it after
/// its scan (the fixed-lag window smoother, docs/window.md).
struct OwnedResidualTerm {
  std::unique_ptr<ceres::CostFunction> cost;
  /// State blocks in the cost's parameter order; Ego() is the state of the
  /// scan the model belongs to (the window rewrites it to EgoAt(that scan's
  /// stamp) when it takes the term over).
  std::vector<StateKey> blocks;
};

class MeasurementModel {
 public:
  virtual ~MeasurementModel() = default;
  /// Short name for diagnostics ("point_to_plane", "active_observation", ...).
  virtual const char* name() const = 0;
  /// Re-linearizes at `x` and appends this iteration's residual blocks to
  /// `*terms` (none is fine: e.g. no plane found). Blocks may name only
  /// teammates present in x's layout and ego states the back end holds. A
  /// non-ok Status aborts the update.
  virtual Status Linearize(const SwarmState& x, std::vector<ResidualTerm>* terms) = 0;
  /// Optional fast path for the posterior covariance: adds J^T J of the
  /// residual blocks of the last Linearize, evaluated at `x`, in the tangent
  /// space and ErrorStateLayout order of x, to `*information` and returns
  /// true. The default returns false and the update evaluates the blocks
  /// itself (cost Jacobians times the manifolds' PlusJacobian).
  virtual bool AddInformation(const SwarmState& x, Eigen::MatrixXd* information) const {
    (void)x;
    (void)information;
    return false;
  }
  /// For a model whose residual blocks are the same wherever they are
  /// evaluated (exact functions of the state, noise fixed when the model was
  /// built: the mutual observations): moves them into `*terms` and returns
  /// true, so that a fixed-lag window can keep them while their scan stays
  /// in the window. The default returns false (the model must be
  /// re-linearized, e.g. point-to-plane re-associates) and moves nothing.
  virtual bool ReleaseTerms(std::vector<OwnedResidualTerm>* terms) {
    (void)terms;
    return false;
  }
};

}  // namespace swarmlio::lio
