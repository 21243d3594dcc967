// A temporary tracker (paper Sec. III-C-1): a constant-velocity Kalman filter
// on a detected object that is not identified yet, with the trajectory it
// accumulates for identification. It coasts (predicts only) while the object
// is not seen and is terminated after max_coast_s without an update.
#pragma once

#include <Eigen/Core>
#include <string>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/teammate/cv_filter.h"
#include "swarmlio/teammate/trajectory_buffer.h"

namespace swarmlio::teammate {

/// YAML section `teammate.temporary`.
struct TemporaryTrackerOptions {
  double max_coast_s = 2.0;  // deleted after this long without an update (hard-coded 2 s)
  int max_trackers = 32;     // new objects beyond this many trackers are ignored
  CvFilterOptions filter;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("max_coast_s", max_coast_s,
      FieldSpec::Positive("s", "a tracker without update for this long is terminated"));
    v("max_trackers", max_trackers, FieldSpec::InRange(0.0, 1e4, "", "most temporary trackers"));
    v("filter", filter);
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

class TemporaryTracker {
 public:
  /// Starts on a detection at `p_in_G`, measured at `stamp_s`.
  TemporaryTracker(int id, double stamp_s, const Eigen::Vector3d& p_in_G,
                   const TemporaryTrackerOptions& options, int trajectory_capacity);

  /// Continues the track of a teammate tracker whose teammate restarted
  /// (TeammateDetector::RestartTeammate): its filter and the positions it
  /// saw, at `stamp_s`.
  TemporaryTracker(int id, double stamp_s, const ConstantVelocityFilter& filter,
                   const TrajectoryBuffer& trajectory);

  /// Predicts to the measurement time and updates with a cluster position;
  /// the updated position joins the trajectory.
  void Update(double stamp_s, const Eigen::Vector3d& p_in_G, const TemporaryTrackerOptions& options);

  /// Predicted position at `stamp_s` (state unchanged).
  Eigen::Vector3d PositionAt(double stamp_s) const { return filter_.PositionAt(stamp_s); }
  bool Expired(double stamp_s, const TemporaryTrackerOptions& options) const {
    return stamp_s - last_update_s_ > options.max_coast_s;
  }

  int id() const { return id_; }
  double created_s() const { return created_s_; }
  double last_update_s() const { return last_update_s_; }
  double last_match_s() const { return last_match_s_; }
  void set_last_match_s(double stamp_s) { last_match_s_ = stamp_s; }
  const ConstantVelocityFilter& filter() const { return filter_; }
  const TrajectoryBuffer& trajectory() const { return trajectory_; }

 private:
  int id_;
  double created_s_;
  double last_update_s_;
  double last_match_s_ = -1e300;
  ConstantVelocityFilter filter_;
  TrajectoryBuffer trajectory_;
};

}  // namespace swarmlio::teammate
