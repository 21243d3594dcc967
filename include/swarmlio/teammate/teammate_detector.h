// TeammateDetector: the initialization pipeline of Swarm-LIO (paper Sec.
// III-C, Alg. 1) and the teammate trackers of Sec. III-D-1, independent of
// the estimator. Per scan:
//
//   1. reflectivity filtering + Euclidean clustering (clustering.h);
//   2. teammate trackers take the nearest cluster within their gate, else
//      re-cluster the raw points in their predicted region; unseen ones are
//      updated from the broadcast odometry (teammate_tracker.h);
//   3. the same for temporary trackers (temporary_tracker.h); clusters left
//      over start new temporary trackers; trackers without update for too
//      long are terminated;
//   4. excited temporary trackers (trajectory_buffer.h) are matched against
//      every teammate's broadcast trajectory (trajectory_matcher.h); an
//      accepted match identifies the teammate, gives the initial T_Gi_Gj and
//      turns the tracker into a teammate tracker;
//   5. outputs: ^{b_i}p_{b_j} for every teammate seen in this scan
//      (observation.h) and the indices of the points on tracked objects, to be
//      removed before mapping (point_removal.h).
//
// Inputs: the scan in the body frame at its stamp (motion-compensated), the
// drone's pose T_Gi_bi at that stamp, and the teammates' broadcast odometry
// with stamps in this drone's clock. Not thread-safe; one per drone.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <vector>

#include "swarmlio/common/time.h"
#include "swarmlio/common/status.h"
#include "swarmlio/teammate/airframe.h"
#include "swarmlio/teammate/clustering.h"
#include "swarmlio/teammate/observation.h"
#include "swarmlio/teammate/odometry_history.h"
#include "swarmlio/teammate/scan_types.h"
#include "swarmlio/teammate/teammate_detector_options.h"
#include "swarmlio/teammate/teammate_tracker.h"
#include "swarmlio/teammate/temporary_tracker.h"
#include "swarmlio/teammate/trajectory_matcher.h"

namespace swarmlio::teammate {

/// A teammate identified in this scan.
struct TeammateIdentification {
  int drone_id = -1;
  int tracker_id = -1;
  int64_t stamp_ns = 0;
  Eigen::Matrix3d R_Gi_Gj = Eigen::Matrix3d::Identity();  // initial global extrinsic
  Eigen::Vector3d p_Gj_in_Gi = Eigen::Vector3d::Zero();
  double mean_residual_m = 0.0;
  double second_best_residual_m = 0.0;  // infinity with a single candidate
  int num_pairs = 0;
};

/// State of one tracker after the scan.
struct TrackerState {
  int tracker_id = -1;
  int drone_id = -1;  // -1: temporary (unidentified)
  Eigen::Vector3d p_in_Gi = Eigen::Vector3d::Zero();  // at the scan stamp
  Eigen::Vector3d v_in_Gi = Eigen::Vector3d::Zero();
  bool seen = false;     // updated from a LiDAR cluster in this scan
  bool created = false;  // started in this scan
};

/// One identification attempt (diagnostics): an excited temporary tracker
/// matched against every teammate's broadcast trajectory.
struct MatchAttempt {
  int tracker_id = -1;
  int trajectory_size = 0;
  double second_singular_value_m2 = 0.0;  // of the tracker's scatter H (eq. 6)
  std::vector<MatchCandidate> candidates;  // one per teammate heard from
  int accepted = -1;                       // index into candidates, or -1
};

struct ScanResult {
  std::vector<TeammateObservation> observations;      // teammates seen in this scan
  std::vector<TeammateIdentification> identifications;  // teammates identified in this scan
  std::vector<int> removed_point_indices;  // ascending: points on tracked objects
  std::vector<TrackerState> trackers;      // teammate trackers first, then temporary
  std::vector<MatchAttempt> match_attempts;
  int num_reflective_points = 0;
  int num_reflective_clusters = 0;
  int num_region_clusterings = 0;
};

class TeammateDetector {
 public:
  /// `self_id`: this drone's id (its own broadcasts are ignored). The options
  /// must be valid (CHECKed; validate configs with Validate() when loading).
  TeammateDetector(int self_id, const TeammateDetectorOptions& options);
  ~TeammateDetector();

  /// Stores a teammate's broadcast (stamp in this drone's clock).
  void AddTeammateOdometry(const TeammateOdometry& odometry);

  /// A teammate's announced airframe (docs/teammate.md "Airframes"): from
  /// now on the reflectivity and size gates admit its body (the lowest
  /// announced min_intensity and the largest size_m, never stricter than the
  /// options), and its observations place its body origin by its reflector
  /// model and add its centroid scatter to the covariance. Ignores its own id
  /// and invalid descriptions (false).
  bool SetTeammateAirframe(int drone_id, const AirframeDescription& airframe);
  /// The reflectivity threshold in force (the options' or lower, above).
  double min_reflectivity() const { return clusterer_.options().min_reflectivity; }

  /// Processes one scan. `stamp_ns`: the time of the points' body frame and of
  /// `T_Gi_bi` (the scan end after motion compensation). Errors: non-finite
  /// pose or stamp.
  Status ProcessScan(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                     const std::vector<ScanPoint>& points, ScanResult* result);

  /// Ids of the identified teammates, ascending.
  std::vector<int> IdentifiedTeammates() const;
  /// The current T_Gi_Gj of an identified teammate; false if not identified.
  bool GlobalExtrinsic(int drone_id, Eigen::Isometry3d* T_Gi_Gj) const;
  /// Replaces T_Gi_Gj with a refined estimate (from the ESIKF); false if not identified.
  bool SetGlobalExtrinsic(int drone_id, const Eigen::Isometry3d& T_Gi_Gj);
  /// Starts tracking a teammate identified elsewhere (the teammate matched
  /// this drone's trajectory and sent its T_Gj_Gi; docs/swarm.md "Mutual
  /// identification"): a teammate tracker at its broadcast position mapped
  /// through T_Gi_Gj. False when already tracked or when no broadcast of it
  /// is close enough to `stamp_ns`.
  bool AddIdentifiedTeammate(int drone_id, int64_t stamp_ns, const Eigen::Matrix3d& R_Gi_Gj,
                             const Eigen::Vector3d& p_Gj_in_Gi);
  /// Forgets a teammate (its tracker and broadcast history), e.g. after it
  /// rebooted (new global frame) or was lost for good; it can be identified
  /// again from new broadcasts. False if nothing was known of it.
  bool ForgetTeammate(int drone_id);
  /// The teammate rebooted (new G_j): as ForgetTeammate, but its tracker's
  /// track goes on as a temporary tracker with the positions it saw (G_i
  /// did not change), so the new session is matched as soon as it has
  /// enough pairs, without a new excitation. `stamp_ns`: now (own clock).
  bool RestartTeammate(int drone_id, int64_t stamp_ns);

  int num_temporary_trackers() const { return static_cast<int>(temporary_.size()); }
  const std::vector<TemporaryTracker>& temporary_trackers() const { return temporary_; }
  const TeammateDetectorOptions& options() const { return options_; }

 private:
  void TrackTeammates(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                      const std::vector<ScanPoint>& points, std::vector<bool>* available,
                      ScanResult* result);
  void TrackTemporary(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                      const std::vector<ScanPoint>& points, std::vector<bool>* available,
                      ScanResult* result);
  void StartTrackers(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                     const std::vector<bool>& available);
  void Identify(int64_t stamp_ns, ScanResult* result);
  // Drops the temporary trackers k with remove[k] (keeps the others' order).
  void RemoveTemporary(const std::vector<bool>& remove);
  void FillOutputs(int64_t stamp_ns, const Eigen::Isometry3d& T_Gi_bi,
                   const std::vector<ScanPoint>& points, ScanResult* result);
  // A cluster in the predicted region around `center_in_b`, drone-sized and
  // within `gate_m` of the centre.
  bool ClusterPredictedRegion(const std::vector<ScanPoint>& points,
                              const Eigen::Vector3d& center_in_b, double radius_m, double gate_m,
                              PointCluster* cluster, ScanResult* result);

  // The announced airframe of `drone_id`, or null.
  const AirframeDescription* AirframeOf(int drone_id) const;

  int self_id_;
  TeammateDetectorOptions options_;
  std::map<int, AirframeDescription> airframes_;  // announced, by drone id
  ReflectiveClusterer clusterer_;
  std::map<int, OdometryHistory> odometry_;  // by drone id
  std::vector<TemporaryTracker> temporary_;
  std::map<int, TeammateTracker> teammates_;  // by drone id
  int next_tracker_id_ = 0;
  // Per-scan scratch.
  std::vector<PointCluster> clusters_;
  std::vector<bool> seen_temporary_;
  std::vector<int> seen_teammates_;
  std::vector<int> created_ids_;
};

}  // namespace swarmlio::teammate
