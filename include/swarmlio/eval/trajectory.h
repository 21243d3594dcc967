// A trajectory to evaluate: the poses T_G_b of a body frame b in a global
// frame G, with optional time stamps.
//
// Stamps are double seconds, not integer nanoseconds: evaluation reproduces
// evo, which reads TUM stamps as float64 and associates them in double
// arithmetic, so pair decisions at |dt| == t_max_diff only match bit for bit
// when the stamps are the same doubles (strtod of the file's text). Bag
// stamps are converted with ToSeconds().
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/StdVector>
#include <cstddef>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::eval {

using PoseVector = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;

struct Trajectory {
  /// Seconds, one per pose, non-decreasing; empty for an unstamped (KITTI)
  /// trajectory.
  std::vector<double> stamps_s;
  /// Pose of the body frame b in the global frame G: p_in_G = T_G_b * p_in_b.
  PoseVector T_G_b;

  size_t size() const { return T_G_b.size(); }
  bool empty() const { return T_G_b.empty(); }
  bool has_stamps() const { return !stamps_s.empty(); }

  /// Positions p_b_in_G as the columns of a 3 x n matrix.
  Eigen::Matrix3Xd Positions() const;

  /// The trajectory restricted to the poses ids (in that order).
  Trajectory Select(const std::vector<size_t>& ids) const;

  /// The pose at `stamp_s`, between the two stamped poses around it
  /// (position linear, rotation slerp). False without stamps, outside the
  /// stamps, or when those two poses are more than `max_gap_s` apart.
  bool PoseAt(double stamp_s, double max_gap_s, Eigen::Isometry3d* T_G_b) const;
};

/// Largest max |R^T R - I| of a pose's rotation part that is accepted as a
/// rotation (rotation blocks read from 6-digit KITTI files are orthonormal to
/// ~1e-6).
inline constexpr double kMaxOrthonormalityError = 1e-4;

/// A stamped trajectory from poses of b in G (e.g. estimator output or bag
/// ground truth): stamps ToSeconds(stamp_ns), rotations from the
/// normalised quaternions. No checks (see ValidateTrajectory).
Trajectory TrajectoryFromPoses(const std::vector<PoseStamped>& poses);

/// Checks that the trajectory is usable: stamps absent or one per pose,
/// finite and non-decreasing; poses finite with a rotation part that is a
/// rotation (max |R^T R - I| < 1e-4, which admits the 6-digit
/// KITTI files, and det > 0). `name` prefixes the message.
Status ValidateTrajectory(const Trajectory& trajectory, const std::string& name);

}  // namespace swarmlio::eval
