// The odometry one teammate has broadcast, kept for trajectory matching and
// for its tracker, and its evaluation at any time with lost messages
// tolerated: between two received messages at most `max_gap_s` apart, the
// position is the cubic Hermite interpolation of the positions and
// velocities; within `max_extrapolation_s` of the nearest message it is
// extrapolated with that message's velocity; elsewhere it is unknown.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <deque>

#include "swarmlio/teammate/scan_types.h"

namespace swarmlio::teammate {

class OdometryHistory {
 public:
  /// Adds a message (any order; a message with an already stored stamp
  /// replaces it). Messages older than `keep_s` before the newest are dropped.
  void Add(const TeammateOdometry& odometry, double keep_s);

  bool empty() const { return messages_.empty(); }
  int size() const { return static_cast<int>(messages_.size()); }
  const TeammateOdometry& newest() const { return messages_.back(); }
  const std::deque<TeammateOdometry>& messages() const { return messages_; }

  /// Position and velocity of the teammate (in its G_j) at `stamp_ns`; false
  /// when no message is close enough (see the file comment).
  bool StateAt(int64_t stamp_ns, double max_gap_s, double max_extrapolation_s,
               Eigen::Vector3d* p_bj_in_Gj, Eigen::Vector3d* v_bj_in_Gj) const;
  /// Attitude R_Gj_bj of the message nearest to `stamp_ns`; false when none is
  /// within `max_age_s`.
  bool AttitudeAt(int64_t stamp_ns, double max_age_s, Eigen::Quaterniond* q_Gj_bj) const;

 private:
  // The message nearest to `stamp_ns` (ties: the later one); null when empty.
  const TeammateOdometry* Nearest(int64_t stamp_ns) const;

  std::deque<TeammateOdometry> messages_;  // sorted by stamp
};

}  // namespace swarmlio::teammate
