// Trajectory of a temporary tracker and its excitation test (paper Sec.
// III-C-2, eq. 6):
//   H = sum_k (p_k - c)(p_k - c)^T over the last K positions, c their centroid;
// the trajectory is excited when the second largest singular value of H is
// large enough (a straight line leaves the rotation about it undetermined).
//
// H is the paper's sum, not a mean: it measures the information the
// trajectory holds about the rotation (the Fisher information of the rigid
// fit grows with it), and samples where the object stood still neither add
// nor dilute it. The threshold therefore depends on the scan rate: Swarm-LIO2
// uses 100 m^2 (traj_matching_start_thresh) on up to 300 positions; at 10 Hz
// that needs ~30 s of +-1 m excitation, so the default here is lower.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <string>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::teammate {

struct StampedPosition {
  int64_t stamp_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

/// YAML section `teammate.excitation`.
struct ExcitationOptions {
  int max_positions = 300;        // pos_num_in_traj: K, positions kept per tracker
  int min_positions = 30;         // 0.1 * pos_num_in_traj: fewer are never excited
  double min_second_singular_value_m2 = 6.0;  // of H, eq. 6 (traj_matching_start_thresh)

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("max_positions", max_positions,
      FieldSpec::InRange(3.0, 1e5, "", "positions kept per tracker (pos_num_in_traj)"));
    v("min_positions", min_positions,
      FieldSpec::InRange(3.0, 1e5, "", "positions needed before the excitation test"));
    v("min_second_singular_value_m2", min_second_singular_value_m2,
      FieldSpec::AtLeast(0.0, "m^2", "second singular value of the scatter H (eq. 6)"));
  }
  std::string Validate() const {
    std::string error = config::ValidateFields(*this);
    if (error.empty() && min_positions > max_positions) {
      error = "min_positions: must not exceed max_positions (" + std::to_string(min_positions) +
              " > " + std::to_string(max_positions) + ")";
    }
    return error;
  }
};

/// The last `capacity` stamped positions of one tracker (oldest first).
class TrajectoryBuffer {
 public:
  explicit TrajectoryBuffer(int capacity = 300) : capacity_(capacity) {}

  /// Appends; drops the oldest beyond the capacity.
  void Push(int64_t stamp_ns, const Eigen::Vector3d& p);
  void Clear() { samples_.clear(); }

  int size() const { return static_cast<int>(samples_.size()); }
  bool empty() const { return samples_.empty(); }
  const std::deque<StampedPosition>& samples() const { return samples_; }

  /// Singular values of H (eq. 6), descending [m^2]. Zero for an empty buffer.
  Eigen::Vector3d ScatterSingularValues() const;

 private:
  int capacity_;
  std::deque<StampedPosition> samples_;
};

/// TrajExcited(T_m) of Alg. 1: enough positions and a second singular value
/// of H above the threshold.
bool IsExcited(const TrajectoryBuffer& trajectory, const ExcitationOptions& options);

/// The second singular value of the scatter H of a set of positions (3xN).
double SecondScatterSingularValue(const Eigen::Ref<const Eigen::Matrix3Xd>& positions);

}  // namespace swarmlio::teammate
