// A temporary tracker (paper Sec. III-C-1): a constant-velocity Kalman filter
// on a detected object that is not identified yet, with the trajectory it
// accumulates for identification. It coasts (predicts only) while the object
// is not seen and is terminated after max_coast_s without an update.
#pragma once

#include <Eigen/Core>
#include <string>

#include "swarmlio/common/time.h"
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
  /// Starts on a detection at `p_in_G`, measured at `stamp_ns`.
  TemporaryTracker(int id, int64_t stamp_ns, const Eigen::Vector3d& p_in_G,
                   const TemporaryTrackerOptions& options, int trajectory_capacity);

  /// Continues the track of a teammate tracker whose teammate restarted
  /// (TeammateDetector::RestartTeammate): its filter and the positions it
  /// saw, at `stamp_ns`.
  TemporaryTracker(int id, int64_t stamp_ns, const ConstantVelocityFilter& filter,
                   const TrajectoryBuffer& trajectory);

  /// Predicts to the measurement time and updates with a cluster position;
  /// the updated position joins the trajectory.
  void Update(int64_t stamp_ns, const Eigen::Vector3d& p_in_G, const TemporaryTrackerOptions& options);

  /// Predicted position at `stamp_ns` (state unchanged).
  Eigen::Vector3d PositionAt(int64_t stamp_ns) const { return filter_.PositionAt(stamp_ns); }
  bool Expired(int64_t stamp_ns, const TemporaryTrackerOptions& options) const {
    return SecondsBetween(last_update_ns_, stamp_ns) > options.max_coast_s;
  }

  int id() const { return id_; }
  int64_t created_ns() const { return created_ns_; }
  int64_t last_update_ns() const { return last_update_ns_; }
  int64_t last_match_ns() const { return last_match_ns_; }
  bool matched_before() const { return matched_before_; }
  void set_last_match_ns(int64_t stamp_ns) {
    last_match_ns_ = stamp_ns;
    matched_before_ = true;
  }
  const ConstantVelocityFilter& filter() const { return filter_; }
  const TrajectoryBuffer& trajectory() const { return trajectory_; }

 private:
  int id_;
  int64_t created_ns_;
  int64_t last_update_ns_;
  int64_t last_match_ns_ = 0;  // valid when matched_before_
  bool matched_before_ = false;
  ConstantVelocityFilter filter_;
  TrajectoryBuffer trajectory_;
};

}  // namespace swarmlio::teammate
