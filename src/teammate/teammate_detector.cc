#include "swarmlio/teammate/teammate_detector.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "swarmlio/common/check.h"
#include "swarmlio/common/time.h"
#include "swarmlio/teammate/association.h"
#include "swarmlio/teammate/point_removal.h"
#include "swarmlio/teammate/trajectory_matcher.h"

namespace swarmlio::teammate {
namespace {

Eigen::Vector3d CentreInB(const PointCluster& cluster, const ObservationOptions& options) {
  return EstimateCentre(cluster, options).p_in_b;
}

}  // namespace

TeammateDetector::TeammateDetector(int self_id, const TeammateDetectorOptions& options)
    : self_id_(self_id), options_(options), clusterer_(options.clustering) {
  const std::string error = options.Validate();
  CHECK(error.empty()) << "invalid TeammateDetectorOptions: " << error;
}

TeammateDetector::~TeammateDetector() = default;

bool TeammateDetector::SetTeammateAirframe(int drone_id, const AirframeDescription& airframe) {
  if (drone_id == self_id_ || drone_id < 0 || !airframe.Validate().empty()) return false;
  airframes_[drone_id] = airframe;
  // The gates admit every announced body; the options stay the floor.
  // Clusters of a body's returns span at most its size plus the range noise.
  constexpr double kSizeMargin = 1.2;
  double min_reflectivity = options_.clustering.min_reflectivity;
  double max_size_m = options_.clustering.max_object_size_m;
  for (const auto& [id, a] : airframes_) {
    min_reflectivity = std::min(min_reflectivity, a.min_intensity);
    max_size_m = std::max(max_size_m, kSizeMargin * a.size_m);
  }
  clusterer_.SetGates(min_reflectivity, max_size_m);
  return true;
}

const AirframeDescription* TeammateDetector::AirframeOf(int drone_id) const {
  const auto it = airframes_.find(drone_id);
  return it == airframes_.end() ? nullptr : &it->second;
}

void TeammateDetector::AddTeammateOdometry(const TeammateOdometry& odometry) {
  if (odometry.drone_id == self_id_ || odometry.drone_id < 0) return;
  if (!odometry.p_bj_in_Gj.allFinite() || !odometry.v_bj_in_Gj.allFinite()) {
    return;
  }
  odometry_[odometry.drone_id].Add(odometry, options_.matching.odometry_keep_s);
}

Status TeammateDetector::ProcessScan(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                                     const std::vector<ScanPoint>& points, ScanResult* result) {
  if (!T_Gi_bi.matrix().allFinite()) {
    return Status::InvalidArgument("teammate detector: non-finite scan pose");
  }
  *result = ScanResult();
  clusterer_.FindReflectiveClusters(points, &clusters_, &result->num_reflective_points);
  result->num_reflective_clusters = static_cast<int>(clusters_.size());
  std::vector<bool> available(clusters_.size());
  for (size_t k = 0; k < clusters_.size(); ++k) available[k] = clusterer_.IsDroneSized(clusters_[k]);

  TrackTeammates(stamp_ns, T_Gi_bi, points, &available, result);
  TrackTemporary(stamp_ns, T_Gi_bi, points, &available, result);
  StartTrackers(stamp_ns, T_Gi_bi, available);
  Identify(stamp_ns, result);
  FillOutputs(stamp_ns, T_Gi_bi, points, result);
  return Status::Ok();
}

bool TeammateDetector::ClusterPredictedRegion(const std::vector<ScanPoint>& points,
                                              const Eigen::Vector3d& center_in_b, double radius_m,
                                              double gate_m, PointCluster* cluster,
                                              ScanResult* result) {
  if (!options_.association.recluster_in_predicted_region) return false;
  const double range = center_in_b.norm();
  if (range > options_.clustering.max_range_m + radius_m) return false;
  ++result->num_region_clusterings;
  if (!clusterer_.ClusterRegion(points, center_in_b, radius_m, cluster)) return false;
  if (!clusterer_.IsDroneSized(*cluster)) return false;
  return (CentreInB(*cluster, options_.observation) - center_in_b).norm() <= gate_m;
}

void TeammateDetector::TrackTeammates(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                                      const std::vector<ScanPoint>& points,
                                      std::vector<bool>* available, ScanResult* result) {
  seen_teammates_.clear();
  if (teammates_.empty()) return;
  const Eigen::Isometry3d T_bi_Gi = T_Gi_bi.inverse();
  std::vector<Eigen::Vector3d> predictions_in_b;
  for (const auto& [id, tracker] : teammates_) {
    predictions_in_b.push_back(
        T_bi_Gi * tracker.PositionAt(stamp_ns, odometry_[id], options_.teammate));
  }
  std::vector<Eigen::Vector3d> centres_in_b;
  for (const PointCluster& c : clusters_) centres_in_b.push_back(CentreInB(c, options_.observation));
  const std::vector<int> assignment = AssociateNearest(
      predictions_in_b, centres_in_b, options_.association.teammate_gate_m, available);

  size_t k = 0;
  for (auto& [id, tracker] : teammates_) {
    const OdometryHistory& history = odometry_[id];
    PointCluster cluster;
    bool seen = false;
    if (assignment[k] >= 0) {
      cluster = clusters_[static_cast<size_t>(assignment[k])];
      seen = true;
    } else {
      seen = ClusterPredictedRegion(points, predictions_in_b[k],
                                    options_.association.teammate_region_radius_m,
                                    options_.association.teammate_gate_m, &cluster, result);
    }
    ++k;
    if (!seen) {
      tracker.UpdateOdometry(stamp_ns, history, options_.teammate);
      continue;
    }
    // The teammate's attitude relative to mine, from its broadcast through
    // T_Gi_Gj, places the body origin behind the tape (observation.h, only
    // with the band model configured).
    const AirframeDescription* airframe = AirframeOf(id);
    Eigen::Quaterniond q_Gj_bj;
    Eigen::Matrix3d R_bi_bj;
    const bool attitude_known =
        (airframe != nullptr || options_.observation.UsesTapeBand()) &&
        history.AttitudeAt(stamp_ns, options_.teammate.max_odometry_age_s, &q_Gj_bj);
    if (attitude_known) {
      R_bi_bj = T_Gi_bi.linear().transpose() * tracker.R_Gi_Gj() * q_Gj_bj.toRotationMatrix();
    }
    const Eigen::Matrix3d* R_bi_bj_known = attitude_known ? &R_bi_bj : nullptr;
    const ClusterCentre centre =
        EstimateCentre(cluster, options_.observation, R_bi_bj_known, airframe);
    tracker.UpdateLidar(stamp_ns + ToNanoseconds(centre.time_offset_s), T_Gi_bi * centre.p_in_b, history,
                        options_.teammate);
    Eigen::Vector3d v_in_Gi = tracker.filter().v();
    tracker.VelocityInGi(stamp_ns, history, options_.teammate, &v_in_Gi);
    if (cluster.centroid_in_b.norm() >= options_.observation.min_range_m) {
      result->observations.push_back(MakeObservation(id, stamp_ns, cluster,
                                                     T_Gi_bi.linear().transpose() * v_in_Gi,
                                                     options_.observation, R_bi_bj_known,
                                                     airframe));
    }
    seen_teammates_.push_back(id);
  }
}

void TeammateDetector::TrackTemporary(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                                      const std::vector<ScanPoint>& points,
                                      std::vector<bool>* available, ScanResult* result) {
  seen_temporary_.assign(temporary_.size(), false);
  if (temporary_.empty()) return;
  const Eigen::Isometry3d T_bi_Gi = T_Gi_bi.inverse();
  std::vector<Eigen::Vector3d> predictions_in_b;
  for (const TemporaryTracker& tracker : temporary_) {
    predictions_in_b.push_back(T_bi_Gi * tracker.PositionAt(stamp_ns));
  }
  std::vector<Eigen::Vector3d> centres_in_b;
  for (const PointCluster& c : clusters_) centres_in_b.push_back(CentreInB(c, options_.observation));
  const std::vector<int> assignment = AssociateNearest(
      predictions_in_b, centres_in_b, options_.association.temporary_gate_m, available);
  for (size_t k = 0; k < temporary_.size(); ++k) {
    PointCluster cluster;
    bool seen = false;
    if (assignment[k] >= 0) {
      cluster = clusters_[static_cast<size_t>(assignment[k])];
      seen = true;
    } else {
      seen = ClusterPredictedRegion(points, predictions_in_b[k],
                                    options_.association.temporary_region_radius_m,
                                    options_.association.temporary_gate_m, &cluster, result);
    }
    if (!seen) continue;
    seen_temporary_[k] = true;
    const ClusterCentre centre = EstimateCentre(cluster, options_.observation);
    temporary_[k].Update(stamp_ns + ToNanoseconds(centre.time_offset_s), T_Gi_bi * centre.p_in_b,
                         options_.temporary);
  }
}

void TeammateDetector::StartTrackers(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                                     const std::vector<bool>& available) {
  created_ids_.clear();
  // Trackers' positions now, in G_i: a leftover cluster near one is the same object.
  std::vector<Eigen::Vector3d> tracked_in_Gi;
  for (const auto& [id, tracker] : teammates_) {
    tracked_in_Gi.push_back(tracker.PositionAt(stamp_ns, odometry_[id], options_.teammate));
  }
  for (const TemporaryTracker& tracker : temporary_) tracked_in_Gi.push_back(tracker.PositionAt(stamp_ns));
  const double same2 = options_.association.same_object_m * options_.association.same_object_m;
  for (size_t k = 0; k < clusters_.size(); ++k) {
    if (!available[k]) continue;
    if (static_cast<int>(temporary_.size()) >= options_.temporary.max_trackers) break;
    const ClusterCentre centre = EstimateCentre(clusters_[k], options_.observation);
    const Eigen::Vector3d p_in_Gi = T_Gi_bi * centre.p_in_b;
    const bool known = std::any_of(tracked_in_Gi.begin(), tracked_in_Gi.end(),
                                   [&](const Eigen::Vector3d& p) {
                                     return (p - p_in_Gi).squaredNorm() <= same2;
                                   });
    if (known) continue;
    const int id = next_tracker_id_++;
    temporary_.emplace_back(id, stamp_ns + ToNanoseconds(centre.time_offset_s), p_in_Gi,
                            options_.temporary, options_.excitation.max_positions);
    seen_temporary_.push_back(true);
    created_ids_.push_back(id);
    tracked_in_Gi.push_back(p_in_Gi);
  }

  // Terminate trackers without update for too long, and duplicates: a
  // temporary tracker on an identified teammate or on the same object as an
  // older temporary tracker (two trackers that converged on one object).
  std::vector<bool> remove(temporary_.size(), false);
  for (size_t a = 0; a < temporary_.size(); ++a) {
    if (temporary_[a].Expired(stamp_ns, options_.temporary)) remove[a] = true;
    const Eigen::Vector3d pa = temporary_[a].PositionAt(stamp_ns);
    for (const auto& [id, tracker] : teammates_) {
      if ((tracker.PositionAt(stamp_ns, odometry_[id], options_.teammate) - pa).squaredNorm() <= same2) {
        remove[a] = true;
      }
    }
    for (size_t b = 0; b < a && !remove[a]; ++b) {
      if (remove[b]) continue;
      if ((temporary_[b].PositionAt(stamp_ns) - pa).squaredNorm() <= same2) {
        // Keep the one with the longer trajectory (ties: the older one, b).
        if (temporary_[a].trajectory().size() > temporary_[b].trajectory().size()) {
          remove[b] = true;
        } else {
          remove[a] = true;
        }
      }
    }
  }
  RemoveTemporary(remove);
}

void TeammateDetector::RemoveTemporary(const std::vector<bool>& remove) {
  size_t kept = 0;
  for (size_t k = 0; k < temporary_.size(); ++k) {
    if (remove[k]) continue;
    if (kept != k) {
      temporary_[kept] = std::move(temporary_[k]);
      seen_temporary_[kept] = seen_temporary_[k];
    }
    ++kept;
  }
  temporary_.erase(temporary_.begin() + static_cast<std::ptrdiff_t>(kept), temporary_.end());
  seen_temporary_.resize(kept);
}

void TeammateDetector::Identify(int64_t stamp_ns, ScanResult* result) {
  std::vector<bool> remove(temporary_.size(), false);
  for (size_t k = 0; k < temporary_.size(); ++k) {
    TemporaryTracker& tracker = temporary_[k];
    if (!seen_temporary_[k]) continue;
    if (tracker.matched_before() &&
        SecondsBetween(tracker.last_match_ns(), stamp_ns) < options_.matching.match_interval_s) {
      continue;
    }
    if (!IsExcited(tracker.trajectory(), options_.excitation)) continue;
    tracker.set_last_match_ns(stamp_ns);
    std::vector<MatchCandidate> candidates;
    for (const auto& [id, history] : odometry_) {
      MatchCandidate candidate;
      candidate.drone_id = id;
      candidate.valid =
          MatchTrajectory(tracker.trajectory(), history, options_.matching, &candidate.match).ok();
      candidates.push_back(candidate);
    }
    double second_best = 0.0;
    const int best = SelectMatch(candidates, options_.matching, &second_best);
    MatchAttempt attempt;
    attempt.tracker_id = tracker.id();
    attempt.trajectory_size = tracker.trajectory().size();
    attempt.second_singular_value_m2 = tracker.trajectory().ScatterSingularValues()(1);
    attempt.candidates = candidates;
    attempt.accepted = best;
    result->match_attempts.push_back(std::move(attempt));
    if (best < 0) continue;
    const MatchCandidate& match = candidates[static_cast<size_t>(best)];
    remove[k] = true;  // it becomes a teammate tracker, or it duplicates one
    if (teammates_.count(match.drone_id) > 0) continue;
    teammates_.emplace(match.drone_id,
                       TeammateTracker(match.drone_id, tracker.id(), match.match.R_Gi_Gj,
                                       match.match.p_Gj_in_Gi, tracker.filter(),
                                       options_.excitation.max_positions));
    TeammateIdentification id;
    id.drone_id = match.drone_id;
    id.tracker_id = tracker.id();
    id.stamp_ns = stamp_ns;
    id.R_Gi_Gj = match.match.R_Gi_Gj;
    id.p_Gj_in_Gi = match.match.p_Gj_in_Gi;
    id.mean_residual_m = match.match.mean_residual_m;
    id.second_best_residual_m = second_best;
    id.num_pairs = match.match.num_pairs;
    result->identifications.push_back(id);
  }
  RemoveTemporary(remove);
}

void TeammateDetector::FillOutputs(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                                   const std::vector<ScanPoint>& points, ScanResult* result) {
  const Eigen::Isometry3d T_bi_Gi = T_Gi_bi.inverse();
  std::vector<Eigen::Vector3d> centres_in_b;
  std::vector<TrackerState> states;
  for (const auto& [id, tracker] : teammates_) {
    TrackerState state;
    state.tracker_id = tracker.tracker_id();
    state.drone_id = id;
    state.p_in_Gi = tracker.PositionAt(stamp_ns, odometry_[id], options_.teammate);
    state.v_in_Gi = tracker.filter().v();
    state.seen = std::find(seen_teammates_.begin(), seen_teammates_.end(), id) !=
                 seen_teammates_.end();
    for (const TeammateIdentification& i : result->identifications) state.created |= (i.drone_id == id);
    states.push_back(state);
    centres_in_b.push_back(T_bi_Gi * state.p_in_Gi);
  }
  for (size_t k = 0; k < temporary_.size(); ++k) {
    const TemporaryTracker& tracker = temporary_[k];
    TrackerState state;
    state.tracker_id = tracker.id();
    state.p_in_Gi = tracker.PositionAt(stamp_ns);
    state.v_in_Gi = tracker.filter().v();
    state.seen = seen_temporary_[k];
    state.created = std::find(created_ids_.begin(), created_ids_.end(), tracker.id()) !=
                    created_ids_.end();
    states.push_back(state);
    if (options_.removal.around_temporary_trackers) centres_in_b.push_back(T_bi_Gi * state.p_in_Gi);
  }
  result->trackers = std::move(states);
  FindPointsNear(points, centres_in_b, options_.removal.radius_m, &result->removed_point_indices);
}

std::vector<int> TeammateDetector::IdentifiedTeammates() const {
  std::vector<int> ids;
  for (const auto& [id, tracker] : teammates_) ids.push_back(id);
  return ids;
}

bool TeammateDetector::GlobalExtrinsic(int drone_id, Eigen::Isometry3d* T_Gi_Gj) const {
  const auto it = teammates_.find(drone_id);
  if (it == teammates_.end()) return false;
  T_Gi_Gj->setIdentity();
  T_Gi_Gj->linear() = it->second.R_Gi_Gj();
  T_Gi_Gj->translation() = it->second.p_Gj_in_Gi();
  return true;
}

bool TeammateDetector::SetGlobalExtrinsic(int drone_id, const Eigen::Isometry3d& T_Gi_Gj) {
  const auto it = teammates_.find(drone_id);
  if (it == teammates_.end()) return false;
  it->second.SetGlobalExtrinsic(T_Gi_Gj.linear(), T_Gi_Gj.translation());
  return true;
}

bool TeammateDetector::AddIdentifiedTeammate(int drone_id, int64_t stamp_ns,
                                             const Eigen::Matrix3d& R_Gi_Gj,
                                             const Eigen::Vector3d& p_Gj_in_Gi) {
  if (teammates_.count(drone_id) > 0) return false;
  const auto it = odometry_.find(drone_id);
  if (it == odometry_.end()) return false;
  const TeammateTrackerOptions& o = options_.teammate;
  Eigen::Vector3d p_bj_in_Gj, v_bj_in_Gj;
  if (!it->second.StateAt(stamp_ns, o.max_odometry_age_s, o.max_odometry_age_s, &p_bj_in_Gj,
                          &v_bj_in_Gj)) {
    return false;
  }
  ConstantVelocityFilter filter;
  filter.Initialize(stamp_ns, R_Gi_Gj * p_bj_in_Gj + p_Gj_in_Gi, R_Gi_Gj * v_bj_in_Gj,
                    o.odometry_position_sigma_m, o.velocity_sigma_m_s);
  teammates_.emplace(drone_id,
                     TeammateTracker(drone_id, next_tracker_id_++, R_Gi_Gj, p_Gj_in_Gi, filter,
                                     options_.excitation.max_positions));
  return true;
}

bool TeammateDetector::RestartTeammate(int drone_id, int64_t stamp_ns) {
  const auto it = teammates_.find(drone_id);
  if (it != teammates_.end() && !it->second.seen_trajectory().empty()) {
    temporary_.emplace_back(it->second.tracker_id(), stamp_ns, it->second.filter(),
                            it->second.seen_trajectory());
    seen_temporary_.push_back(false);
  }
  return ForgetTeammate(drone_id);
}

bool TeammateDetector::ForgetTeammate(int drone_id) {
  const bool known = teammates_.erase(drone_id) > 0;
  return odometry_.erase(drone_id) > 0 || known;
}

}  // namespace swarmlio::teammate
