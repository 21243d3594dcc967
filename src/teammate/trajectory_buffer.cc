#include "swarmlio/teammate/trajectory_buffer.h"

#include <Eigen/Eigenvalues>

namespace swarmlio::teammate {
namespace {

// H is symmetric positive semi-definite: its singular values are its
// eigenvalues. Returned descending.
Eigen::Vector3d SortedEigenvalues(const Eigen::Matrix3d& scatter) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ascending = solver.eigenvalues().cwiseMax(0.0);
  return Eigen::Vector3d(ascending(2), ascending(1), ascending(0));
}

}  // namespace

void TrajectoryBuffer::Push(int64_t stamp_ns, const Eigen::Vector3d& p) {
  samples_.push_back({stamp_ns, p});
  while (static_cast<int>(samples_.size()) > capacity_) samples_.pop_front();
}

Eigen::Vector3d TrajectoryBuffer::ScatterSingularValues() const {
  if (samples_.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const StampedPosition& s : samples_) mean += s.p;
  mean /= static_cast<double>(samples_.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const StampedPosition& s : samples_) {
    const Eigen::Vector3d d = s.p - mean;
    scatter += d * d.transpose();
  }
  return SortedEigenvalues(scatter);
}

bool IsExcited(const TrajectoryBuffer& trajectory, const ExcitationOptions& options) {
  if (trajectory.size() < options.min_positions) return false;
  return trajectory.ScatterSingularValues()(1) > options.min_second_singular_value_m2;
}

double SecondScatterSingularValue(const Eigen::Ref<const Eigen::Matrix3Xd>& positions) {
  if (positions.cols() == 0) return 0.0;
  const Eigen::Vector3d mean = positions.rowwise().mean();
  const Eigen::Matrix3Xd centered = positions.colwise() - mean;
  return SortedEigenvalues(centered * centered.transpose())(1);
}

}  // namespace swarmlio::teammate
