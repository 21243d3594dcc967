#include "swarmlio/math/umeyama.h"

#include <Eigen/SVD>
#include <cmath>
#include <string>

namespace swarmlio {

Status AlignUmeyama(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                    const Eigen::Ref<const Eigen::Matrix3Xd>& dst, const UmeyamaOptions& options,
                    UmeyamaResult* result) {
  if (src.cols() != dst.cols()) {
    return Status::InvalidArgument("umeyama: " + std::to_string(src.cols()) + " source points but " +
                                   std::to_string(dst.cols()) + " destination points");
  }
  if (src.cols() < 3) {
    return Status::InvalidArgument("umeyama: need at least 3 point pairs, got " +
                                   std::to_string(src.cols()));
  }
  if (!src.allFinite() || !dst.allFinite()) {
    return Status::InvalidArgument("umeyama: non-finite coordinates");
  }
  const Eigen::Index n = src.cols();
  const Eigen::Vector3d mean_src =
      options.with_translation ? Eigen::Vector3d(src.rowwise().mean()) : Eigen::Vector3d::Zero();
  const Eigen::Matrix3Xd centered = src.colwise() - mean_src;
  const Eigen::Matrix3d scatter = centered * centered.transpose() / static_cast<double>(n);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(scatter);
  const Eigen::Vector3d singular = svd.singularValues();
  if (singular(1) <= options.min_second_singular_value_m2 || singular(0) <= 0.0) {
    return Status::FailedPrecondition(
        "umeyama: degenerate source points (scatter singular values " + std::to_string(singular(0)) +
        ", " + std::to_string(singular(1)) + " m^2; need the second > " +
        std::to_string(options.min_second_singular_value_m2) + ")");
  }
  UmeyamaResult out;
  if (options.with_translation) {
    const Eigen::Matrix4d T = Eigen::umeyama(src, dst, options.with_scale);
    // Eigen folds the scale into the top-left block: R_scaled = s R.
    out.scale = options.with_scale ? std::cbrt(T.topLeftCorner<3, 3>().determinant()) : 1.0;
    out.R_dst_src = T.topLeftCorner<3, 3>() / out.scale;
    out.t_dst_src = T.topRightCorner<3, 1>();
  } else {
    // The same formulas about the origin: Sigma = (1/n) sum dst_i src_i^T.
    const Eigen::Matrix3d sigma = dst * src.transpose() / static_cast<double>(n);
    const Eigen::JacobiSVD<Eigen::Matrix3d> cross(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Vector3d S = Eigen::Vector3d::Ones();
    if ((cross.matrixU() * cross.matrixV().transpose()).determinant() < 0.0) S(2) = -1.0;
    out.R_dst_src = cross.matrixU() * S.asDiagonal() * cross.matrixV().transpose();
    out.scale = options.with_scale ? cross.singularValues().dot(S) / scatter.trace() : 1.0;
    out.t_dst_src.setZero();
  }
  out.source_scatter_singular_values = singular;
  Eigen::Matrix3Xd residual = dst - (out.scale * out.R_dst_src) * src;
  residual.colwise() -= out.t_dst_src;
  out.rms_residual_m = std::sqrt(residual.colwise().squaredNorm().mean());
  *result = out;
  return Status::Ok();
}

}  // namespace swarmlio
