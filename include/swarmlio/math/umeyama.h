// Closed-form least-squares alignment of two point sets (Umeyama 1991).
//
// Finds the similarity (s, R, t) minimising
//     (1/n) sum_i | dst_i - (s R src_i + t) |^2,
// with s fixed to 1 for a rigid (SE(3), Kabsch) alignment. With
//     mu_x = mean(src), mu_y = mean(dst), sigma_x^2 = (1/n) sum |src_i - mu_x|^2,
//     Sigma = (1/n) sum (dst_i - mu_y)(src_i - mu_x)^T = U D V^T,
//     S = diag(1, 1, det(U) det(V)),
// the solution is R = U S V^T, s = tr(D S) / sigma_x^2, t = mu_y - s R mu_x.
// This is the alignment evo and TUM's evaluate_ate.py use; the arithmetic is
// Eigen::umeyama's, wrapped with input checks and a degeneracy test.
// Without translation (with_translation = false) the same solution about the
// origin: mu_x = mu_y = 0 above, t = 0 (a rotation, or similarity, about a
// point both sets share, e.g. a trajectory's first pose).
//
// Used by trajectory evaluation (APE alignment) and by teammate identification
// (trajectory matching, src = positions in G_j, dst = positions in G_i, which
// yields T_Gi_Gj).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "swarmlio/common/status.h"

namespace swarmlio {

struct UmeyamaResult {
  Eigen::Matrix3d R_dst_src = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_dst_src = Eigen::Vector3d::Zero();
  double scale = 1.0;
  /// Root mean square of |dst_i - (s R src_i + t)| at the solution (m).
  double rms_residual_m = 0.0;
  /// Singular values of the source scatter (1/n) sum (x - mu)(x - mu)^T
  /// (mu = 0 without translation),
  /// descending (m^2): how well the source set constrains the rotation.
  Eigen::Vector3d source_scatter_singular_values = Eigen::Vector3d::Zero();

  /// Applies the similarity to a source point.
  Eigen::Vector3d Apply(const Eigen::Vector3d& src) const { return scale * (R_dst_src * src) + t_dst_src; }
};

struct UmeyamaOptions {
  bool with_scale = false;
  /// false: no translation; the sets are not centred, the scatter and the
  /// degeneracy test are taken about the origin.
  bool with_translation = true;
  /// The alignment is refused when the second largest singular value of the
  /// source scatter is below this (m^2): collinear or coincident points leave
  /// a rotation about their line undetermined. 0 accepts any set of >= 3 points.
  double min_second_singular_value_m2 = 0.0;
};

/// Aligns src onto dst (columns are corresponding points). Errors: different
/// sizes, fewer than 3 points, non-finite values, a degenerate source set.
Status AlignUmeyama(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                    const Eigen::Ref<const Eigen::Matrix3Xd>& dst, const UmeyamaOptions& options,
                    UmeyamaResult* result);

}  // namespace swarmlio
