// Teammate identification by trajectory matching (paper Sec. III-C-2, eq. 5):
//
//   T_Gi_Gj = argmin_T sum_k 1/2 | p_m,k - T p_bj,k |^2
//
// over the last K tracker positions p_m,k (in G_i) that have a teammate
// position p_bj,k (in G_j) at the same time. The teammate's position at a
// tracker time comes from OdometryHistory::StateAt (cubic interpolation
// between received messages, so lost messages only remove pairs). The fit is
// the closed-form rigid (no scale) Umeyama/Kabsch alignment, src = teammate
// positions, dst = tracker positions.
//
// The identification decision uses the mean residual of that fit over all
// pairs (the paper's criterion). The transform returned is refined once
// without the outlier pairs (residual above max(outlier_min_m,
// outlier_median_factor * median residual)): a tracker that briefly followed
// a wrong cluster, or a badly seen airframe, must not tilt T_Gi_Gj.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/teammate/odometry_history.h"
#include "swarmlio/teammate/trajectory_buffer.h"

namespace swarmlio::teammate {

/// YAML section `teammate.matching`.
struct MatchingOptions {
  int window_size = 300;             // K: the most recent associated pairs used
  int min_pairs = 30;                // fewer pairs: no decision (Swarm-LIO2: 50 at 30 Hz)
  double max_gap_s = 0.35;           // longest gap between two messages interpolated across
  double max_extrapolation_s = 0.05; // beyond the nearest message, no pair
  double max_mean_residual_m = 0.2;  // ave_match_error_thresh: accept below
  double min_second_best_ratio = 3.0;  // the runner-up's residual must be this many times larger
  double min_source_second_singular_value_m2 = 0.01;  // of the teammate side's MEAN scatter
  double outlier_min_m = 0.05;        // pairs with a residual above both this ...
  double outlier_median_factor = 3.0;  // ... and this times the median are outliers in the refit
  double match_interval_s = 0.5;     // a tracker is matched at most this often
  double odometry_keep_s = 60.0;     // broadcast history kept per teammate

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("window_size", window_size, FieldSpec::InRange(3.0, 1e5, "", "most recent pairs matched (K)"));
    v("min_pairs", min_pairs, FieldSpec::InRange(3.0, 1e5, "", "pairs needed for a decision"));
    v("max_gap_s", max_gap_s,
      FieldSpec::Positive("s", "longest gap between received messages that is interpolated"));
    v("max_extrapolation_s", max_extrapolation_s,
      FieldSpec::AtLeast(0.0, "s", "extrapolation from the nearest message"));
    v("max_mean_residual_m", max_mean_residual_m,
      FieldSpec::Positive("m", "mean alignment residual below which a match is accepted"));
    v("min_second_best_ratio", min_second_best_ratio,
      FieldSpec::AtLeast(1.0, "", "runner-up residual / best residual needed to accept"));
    v("min_source_second_singular_value_m2", min_source_second_singular_value_m2,
      FieldSpec::AtLeast(0.0, "m^2", "second singular value of the mean scatter of the teammate's matched positions"));
    v("outlier_min_m", outlier_min_m,
      FieldSpec::AtLeast(0.0, "m", "residuals below this are never outliers in the refit"));
    v("outlier_median_factor", outlier_median_factor,
      FieldSpec::AtLeast(1.0, "", "outlier threshold in the refit, times the median residual"));
    v("match_interval_s", match_interval_s,
      FieldSpec::AtLeast(0.0, "s", "minimum time between two matchings of one tracker"));
    v("odometry_keep_s", odometry_keep_s,
      FieldSpec::Positive("s", "received odometry kept per teammate"));
  }
  std::string Validate() const {
    std::string error = config::ValidateFields(*this);
    if (error.empty() && min_pairs > window_size) {
      error = "min_pairs: must not exceed window_size (" + std::to_string(min_pairs) + " > " +
              std::to_string(window_size) + ")";
    }
    return error;
  }
};

struct TrajectoryMatch {
  int num_pairs = 0;
  double mean_residual_m = 0.0;  // mean |p_m - T p_bj| of the fit on all pairs
  int num_inliers = 0;           // pairs kept in the refit
  double inlier_mean_residual_m = 0.0;  // mean residual of the refit on its inliers
  // The refined transform (the fit on all pairs when nothing was rejected).
  Eigen::Matrix3d R_Gi_Gj = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_Gj_in_Gi = Eigen::Vector3d::Zero();
  double rms_residual_m = 0.0;   // of the fit on all pairs
  Eigen::Vector3d source_scatter_singular_values = Eigen::Vector3d::Zero();  // of the teammate side, m^2
};

/// TrajMatching(T_j, T_m) of Alg. 1. Errors: fewer than min_pairs pairs
/// (FailedPrecondition), a degenerate teammate trajectory (FailedPrecondition).
Status MatchTrajectory(const TrajectoryBuffer& tracker_in_Gi, const OdometryHistory& teammate,
                       const MatchingOptions& options, TrajectoryMatch* match);

/// One teammate's match result, for the decision below.
struct MatchCandidate {
  int drone_id = -1;
  bool valid = false;  // MatchTrajectory succeeded
  TrajectoryMatch match;
};

/// The identification decision: the best valid candidate is accepted when its
/// mean residual is below max_mean_residual_m and every other valid
/// candidate's residual is at least min_second_best_ratio times larger.
/// Returns the index into `candidates` or -1.
/// `second_best_residual_m` (optional) receives the runner-up's residual
/// (infinity when there is none).
int SelectMatch(const std::vector<MatchCandidate>& candidates, const MatchingOptions& options,
                double* second_best_residual_m = nullptr);

}  // namespace swarmlio::teammate
