#include "swarmlio/teammate/trajectory_matcher.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "swarmlio/math/umeyama.h"

namespace swarmlio::teammate {
namespace {

// |dst_k - (R src_k + t)| for every pair.
Eigen::VectorXd Residuals(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                          const Eigen::Ref<const Eigen::Matrix3Xd>& dst, const UmeyamaResult& fit) {
  Eigen::Matrix3Xd residual = (fit.R_dst_src * src).colwise() + fit.t_dst_src;
  residual -= dst;
  return residual.colwise().norm().transpose();
}

}  // namespace

Status MatchTrajectory(const TrajectoryBuffer& tracker_in_Gi, const OdometryHistory& teammate,
                       const MatchingOptions& options, TrajectoryMatch* match) {
  const auto& samples = tracker_in_Gi.samples();
  // Walk back from the newest tracker position, collecting pairs until K.
  Eigen::Matrix3Xd src(3, std::min<int>(options.window_size, tracker_in_Gi.size()));
  Eigen::Matrix3Xd dst(3, src.cols());
  int n = 0;
  for (auto it = samples.rbegin(); it != samples.rend() && n < src.cols(); ++it) {
    Eigen::Vector3d p_bj_in_Gj;
    if (!teammate.StateAt(it->stamp_ns, options.max_gap_s, options.max_extrapolation_s, &p_bj_in_Gj,
                          nullptr)) {
      continue;
    }
    src.col(n) = p_bj_in_Gj;
    dst.col(n) = it->p;
    ++n;
  }
  match->num_pairs = n;
  if (n < options.min_pairs) {
    return Status::FailedPrecondition("trajectory matching: " + std::to_string(n) +
                                      " time-associated pairs, need " +
                                      std::to_string(options.min_pairs));
  }
  UmeyamaOptions umeyama;
  umeyama.with_scale = false;
  umeyama.min_second_singular_value_m2 = options.min_source_second_singular_value_m2;
  UmeyamaResult result;
  SWARMLIO_RETURN_IF_ERROR(AlignUmeyama(src.leftCols(n), dst.leftCols(n), umeyama, &result)
                               .WithContext("trajectory matching"));
  TrajectoryMatch out;
  out.num_pairs = n;
  out.R_Gi_Gj = result.R_dst_src;
  out.p_Gj_in_Gi = result.t_dst_src;
  out.rms_residual_m = result.rms_residual_m;
  out.source_scatter_singular_values = result.source_scatter_singular_values;
  const Eigen::VectorXd residual = Residuals(src.leftCols(n), dst.leftCols(n), result);
  out.mean_residual_m = residual.mean();
  out.num_inliers = n;
  out.inlier_mean_residual_m = out.mean_residual_m;

  // Refit without the outliers.
  std::vector<double> sorted(residual.data(), residual.data() + n);
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double threshold =
      std::max(options.outlier_min_m, options.outlier_median_factor * sorted[static_cast<size_t>(n / 2)]);
  int m = 0;
  for (int k = 0; k < n; ++k) {
    if (residual(k) > threshold) continue;
    src.col(m) = src.col(k);
    dst.col(m) = dst.col(k);
    ++m;
  }
  UmeyamaResult refined;
  if (m < n && m >= options.min_pairs &&
      AlignUmeyama(src.leftCols(m), dst.leftCols(m), umeyama, &refined).ok()) {
    out.R_Gi_Gj = refined.R_dst_src;
    out.p_Gj_in_Gi = refined.t_dst_src;
    out.num_inliers = m;
    out.inlier_mean_residual_m = Residuals(src.leftCols(m), dst.leftCols(m), refined).mean();
  }
  *match = out;
  return Status::Ok();
}

int SelectMatch(const std::vector<MatchCandidate>& candidates, const MatchingOptions& options,
                double* second_best_residual_m) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  int best = -1;
  double best_residual = kInf, second_residual = kInf;
  for (size_t k = 0; k < candidates.size(); ++k) {
    if (!candidates[k].valid) continue;
    const double r = candidates[k].match.mean_residual_m;
    if (r < best_residual) {
      second_residual = best_residual;
      best_residual = r;
      best = static_cast<int>(k);
    } else if (r < second_residual) {
      second_residual = r;
    }
  }
  if (second_best_residual_m != nullptr) *second_best_residual_m = second_residual;
  if (best < 0 || !(best_residual < options.max_mean_residual_m)) return -1;
  if (second_residual < options.min_second_best_ratio * best_residual) return -1;
  return best;
}

}  // namespace swarmlio::teammate
