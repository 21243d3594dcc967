#include "src/lio/esikf_teammate_subset.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <string>

#include "swarmlio/math/so3.h"

namespace swarmlio::lio::internal {

// Rows/columns of `layout` that a sub-layout with teammates `ids` keeps, in
// the sub-layout's order.
std::vector<int> SubsetIndices(const ErrorStateLayout& layout, const std::vector<int>& ids) {
  std::vector<int> idx;
  for (int k = 0; k < ErrorStateLayout::kEgoDim; ++k) idx.push_back(k);
  for (int id : ids) {
    const Segment s = layout.TeammateBlock(id);
    for (int k = s.offset; k < s.end(); ++k) idx.push_back(k);
  }
  return idx;
}

SwarmState SubsetState(const SwarmState& x, const std::vector<int>& ids) {
  SwarmState sub;
  sub.ego = x.ego;
  for (int id : ids) sub.AddTeammate(id, x.teammate(id));
  return sub;
}

Eigen::MatrixXd Gather(const Eigen::MatrixXd& P, const std::vector<int>& rows,
                       const std::vector<int>& cols) {
  Eigen::MatrixXd out(rows.size(), cols.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    for (size_t c = 0; c < cols.size(); ++c) out(r, c) = P(rows[r], cols[c]);
  }
  return out;
}

// The blocks of a partial update: `ids`, the teammates in the solve
// (estimated and considered) in layout order, and `considered`. Every listed
// id must be present, once, and in one list only.
Status SelectTeammates(const ErrorStateLayout& layout,
                       const std::vector<int>* estimated_teammates,
                       const std::vector<int>* considered_teammates,
                       std::vector<int>* ids,
                       std::vector<int>* considered) {
  const auto listed = [](const std::vector<int>* list, int id) {
    return list != nullptr && std::find(list->begin(), list->end(), id) != list->end();
  };
  size_t num_estimated = 0;
  for (int id : layout.teammate_ids()) {
    const bool is_considered = listed(considered_teammates, id);
    const bool is_estimated =
        estimated_teammates == nullptr ? !is_considered : listed(estimated_teammates, id);
    if (is_considered && is_estimated) {
      return Status::InvalidArgument("EsikfUpdate: teammate " + std::to_string(id) +
                                     " is both estimated and considered");
    }
    if (is_considered) considered->push_back(id);
    if (is_estimated) ++num_estimated;
    if (is_considered || is_estimated) ids->push_back(id);
  }
  if ((estimated_teammates != nullptr && num_estimated != estimated_teammates->size()) ||
      (considered_teammates != nullptr && considered->size() != considered_teammates->size())) {
    return Status::InvalidArgument(
        "EsikfUpdate: estimated_teammates or considered_teammates names a teammate absent from "
        "the state (or twice)");
  }
  return Status::Ok();
}

// The indices in [0, dim) that `idx` does not hold, ascending.
std::vector<int> Complement(const std::vector<int>& idx, int dim) {
  std::vector<int> rest;
  for (int k = 0; k < dim; ++k) {
    if (std::find(idx.begin(), idx.end(), k) == idx.end()) rest.push_back(k);
  }
  return rest;
}

// Schmidt-Kalman: P_os^+ = P_os (I - K H)^T in the tangent space at the
// solution x_s, i.e. P_os P_ss^-1 J P_ss^+ with J = d(x (-) x_hat)/d dx at
// the solution (identity at x_hat; docs/esikf.md).
Eigen::MatrixXd SchmidtKalmanCrossCovariance(const SwarmState& x_hat_s,
                                             const SwarmState& x_s,
                                             const std::vector<int>& ids,
                                             const Eigen::MatrixXd& P_os,
                                             const Eigen::MatrixXd& P_ss,
                                             const Eigen::MatrixXd& P_ss_plus) {
  const Eigen::VectorXd e = x_s.BoxMinus(x_hat_s);
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(x_hat_s.Dim(), x_hat_s.Dim());
  J.block<3, 3>(0, 0) = so3::RightJacobianInverse(e.head<3>());
  for (int id : ids) {
    const int o = x_hat_s.layout().TeammateRotation(id).offset;
    J.block<3, 3>(o, o) = so3::RightJacobianInverse(e.segment<3>(o));
  }
  return P_ss.llt().solve(P_os.transpose()).transpose() * J * P_ss_plus;
}

// Writes the sub-update's covariance P_ss^+ and the cross-covariance
// P_os^+ (and its transpose) into the full P.
void ScatterCovariance(const std::vector<int>& s_idx,
                       const std::vector<int>& o_idx,
                       const Eigen::MatrixXd& P_ss_plus,
                       const Eigen::MatrixXd& P_os_plus,
                       Eigen::MatrixXd* P_out) {
  Eigen::MatrixXd& P = *P_out;
  for (size_t r = 0; r < s_idx.size(); ++r) {
    for (size_t c = 0; c < s_idx.size(); ++c) P(s_idx[r], s_idx[c]) = P_ss_plus(r, c);
  }
  for (size_t r = 0; r < o_idx.size(); ++r) {
    for (size_t c = 0; c < s_idx.size(); ++c) {
      P(o_idx[r], s_idx[c]) = P(s_idx[c], o_idx[r]) = P_os_plus(r, c);
    }
  }
}

// Considered blocks: held at x_hat in the solve (RunAll), whose joint step
// gives the estimated blocks the Schmidt-Kalman gain and cross-covariance
// (its gain rows for them are (P_ss H_s^T + P_sc H_c^T) S^-1); they are not
// corrected: their covariance with every block not estimated (`o_idx` and
// the considered blocks) is restored from P_hat.
void RestoreConsideredCovariance(const ErrorStateLayout& layout,
                                 const std::vector<int>& considered,
                                 const std::vector<int>& o_idx,
                                 const Eigen::MatrixXd& P_hat,
                                 Eigen::MatrixXd* P_out) {
  Eigen::MatrixXd& P = *P_out;
  std::vector<int> not_estimated = o_idx;
  for (int id : considered) {
    const Segment b = layout.TeammateBlock(id);
    for (int k = b.offset; k < b.end(); ++k) not_estimated.push_back(k);
  }
  for (int id : considered) {
    const Segment b = layout.TeammateBlock(id);
    for (int r = b.offset; r < b.end(); ++r) {
      for (int k : not_estimated) P(r, k) = P(k, r) = P_hat(r, k);
    }
  }
}

}  // namespace swarmlio::lio::internal
