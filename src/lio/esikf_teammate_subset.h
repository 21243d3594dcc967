// The teammate subset of a partial ESIKF update (EsikfUpdate::Run with
// estimated / considered teammates, docs/esikf.md): which blocks take part,
// the sub-state and sub-covariance, and the Schmidt-Kalman covariance of the
// blocks left out. Internal to src/lio.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio::internal {

// Rows/columns of `layout` that a sub-layout with teammates `ids` keeps, in
// the sub-layout's order.
std::vector<int> SubsetIndices(const ErrorStateLayout& layout, const std::vector<int>& ids);

SwarmState SubsetState(const SwarmState& x, const std::vector<int>& ids);

Eigen::MatrixXd Gather(const Eigen::MatrixXd& P, const std::vector<int>& rows,
                       const std::vector<int>& cols);

// The blocks of a partial update: `ids`, the teammates in the solve
// (estimated and considered) in layout order, and `considered`. Every listed
// id must be present, once, and in one list only.
Status SelectTeammates(const ErrorStateLayout& layout,
                       const std::vector<int>* estimated_teammates,
                       const std::vector<int>* considered_teammates,
                       std::vector<int>* ids,
                       std::vector<int>* considered);

// The indices in [0, dim) that `idx` does not hold, ascending.
std::vector<int> Complement(const std::vector<int>& idx, int dim);

// Schmidt-Kalman: P_os^+ = P_os (I - K H)^T in the tangent space at the
// solution x_s, i.e. P_os P_ss^-1 J P_ss^+ with J = d(x (-) x_hat)/d dx at
// the solution (identity at x_hat; docs/esikf.md).
Eigen::MatrixXd SchmidtKalmanCrossCovariance(const SwarmState& x_hat_s,
                                             const SwarmState& x_s,
                                             const std::vector<int>& ids,
                                             const Eigen::MatrixXd& P_os,
                                             const Eigen::MatrixXd& P_ss,
                                             const Eigen::MatrixXd& P_ss_plus);

// Writes the sub-update's covariance P_ss^+ and the cross-covariance
// P_os^+ (and its transpose) into the full P.
void ScatterCovariance(const std::vector<int>& s_idx,
                       const std::vector<int>& o_idx,
                       const Eigen::MatrixXd& P_ss_plus,
                       const Eigen::MatrixXd& P_os_plus,
                       Eigen::MatrixXd* P_out);

// Considered blocks: held at x_hat in the solve (RunAll), whose joint step
// gives the estimated blocks the Schmidt-Kalman gain and cross-covariance
// (its gain rows for them are (P_ss H_s^T + P_sc H_c^T) S^-1); they are not
// corrected: their covariance with every block not estimated (`o_idx` and
// the considered blocks) is restored from P_hat.
void RestoreConsideredCovariance(const ErrorStateLayout& layout,
                                 const std::vector<int>& considered,
                                 const std::vector<int>& o_idx,
                                 const Eigen::MatrixXd& P_hat,
                                 Eigen::MatrixXd* P_out);

}  // namespace swarmlio::lio::internal
