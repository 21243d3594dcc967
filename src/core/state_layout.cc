#include "swarmlio/state/state_layout.h"

#include <algorithm>

#include "swarmlio/common/check.h"

namespace swarmlio {

int ErrorStateLayout::SlotOf(int id) const {
  const auto it = std::find(teammate_ids_.begin(), teammate_ids_.end(), id);
  return it == teammate_ids_.end() ? -1 : static_cast<int>(it - teammate_ids_.begin());
}

Segment ErrorStateLayout::TeammateBlock(int id) const {
  const int slot = SlotOf(id);
  CHECK_GE(slot, 0) << "teammate " << id << " is not in the state";
  return Segment{kEgoDim + kTeammateDim * slot, kTeammateDim};
}

Segment ErrorStateLayout::TeammateRotation(int id) const {
  return Segment{TeammateBlock(id).offset + kTeammateRotationOffset, 3};
}

Segment ErrorStateLayout::TeammateTranslation(int id) const {
  return Segment{TeammateBlock(id).offset + kTeammateTranslationOffset, 3};
}

Segment ErrorStateLayout::AddTeammate(int id) {
  CHECK(!HasTeammate(id)) << "teammate " << id << " is already in the state";
  teammate_ids_.push_back(id);
  return TeammateBlock(id);
}

Segment ErrorStateLayout::RemoveTeammate(int id) {
  const Segment block = TeammateBlock(id);
  teammate_ids_.erase(teammate_ids_.begin() + SlotOf(id));
  return block;
}

void AppendCovarianceBlock(const Eigen::MatrixXd& P_new, Eigen::MatrixXd* P) {
  CHECK_EQ(P_new.rows(), P_new.cols());
  CHECK_EQ(P->rows(), P->cols());
  const Eigen::Index n = P->rows();
  const Eigen::Index m = P_new.rows();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n + m, n + m);
  out.topLeftCorner(n, n) = *P;
  out.bottomRightCorner(m, m) = P_new;
  *P = std::move(out);
}

void EraseCovarianceBlock(const Segment& segment, Eigen::MatrixXd* P) {
  CHECK_EQ(P->rows(), P->cols());
  CHECK_GE(segment.offset, 0);
  CHECK_LE(segment.end(), P->rows());
  const Eigen::Index n = P->rows();
  const Eigen::Index a = segment.offset;
  const Eigen::Index s = segment.size;
  const Eigen::Index b = n - a - s;  // size of the part after the segment
  Eigen::MatrixXd out(n - s, n - s);
  out.topLeftCorner(a, a) = P->topLeftCorner(a, a);
  out.topRightCorner(a, b) = P->topRightCorner(a, b);
  out.bottomLeftCorner(b, a) = P->bottomLeftCorner(b, a);
  out.bottomRightCorner(b, b) = P->bottomRightCorner(b, b);
  *P = std::move(out);
}

}  // namespace swarmlio
