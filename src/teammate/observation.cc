#include "swarmlio/teammate/observation.h"

#include <cmath>

namespace swarmlio::teammate {

Eigen::Matrix3d ObservationCovariance(const Eigen::Vector3d& p_in_b,
                                      const ObservationOptions& options) {
  const double range = p_in_b.norm();
  const double lateral = options.lateral_sigma_m + range * options.lateral_sigma_per_range_rad;
  if (range <= 0.0) return lateral * lateral * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d u = p_in_b / range;
  const Eigen::Matrix3d along = u * u.transpose();
  return options.range_sigma_m * options.range_sigma_m * along +
         lateral * lateral * (Eigen::Matrix3d::Identity() - along);
}

Eigen::Vector3d TapeCentroidInBody(const Eigen::Vector3d& u_in_bj, double a, double b) {
  const double ux = u_in_bj.x(), uy = u_in_bj.y();
  const double denominator = b * std::abs(ux) + a * std::abs(uy);
  // Seen from straight above or below, the band shows no side face.
  if (denominator <= 1e-9) return Eigen::Vector3d::Zero();
  return (a * b / denominator) * Eigen::Vector3d(ux, uy, 0.0);
}

ClusterCentre EstimateCentre(const PointCluster& cluster, const ObservationOptions& options,
                             const Eigen::Matrix3d* R_bi_bj, const AirframeDescription* airframe) {
  ClusterCentre centre;
  const bool tape_only = cluster.num_reflective_points >= options.min_reflective_points;
  if (tape_only) {
    centre.p_in_b = cluster.reflective_centroid_in_b;
    centre.time_offset_s = cluster.reflective_mean_time_offset_s;
  } else {
    centre.p_in_b = cluster.centroid_in_b;
    centre.time_offset_s = cluster.mean_time_offset_s;
  }
  const double range = centre.p_in_b.norm();
  if (range <= 0.0) return centre;
  if (tape_only && airframe != nullptr && R_bi_bj != nullptr) {
    const Eigen::Vector3d u_in_bj = R_bi_bj->transpose() * (-centre.p_in_b / range);
    centre.p_in_b -= *R_bi_bj * (airframe->reflector_centre_in_body_m +
                                 VisibleReflectorCentroid(*airframe, u_in_bj));
  } else if (tape_only && options.UsesTapeBand() && R_bi_bj != nullptr) {
    const Eigen::Vector3d u_in_bj = R_bi_bj->transpose() * (-centre.p_in_b / range);
    centre.p_in_b -= *R_bi_bj * TapeCentroidInBody(u_in_bj, options.tape_half_length_m,
                                                  options.tape_half_width_m);
  } else {
    centre.p_in_b += options.centroid_depth_offset_m * centre.p_in_b / range;
  }
  return centre;
}

TeammateObservation MakeObservation(int drone_id, int64_t stamp_ns, const PointCluster& cluster,
                                    const Eigen::Vector3d& v_bj_in_bi,
                                    const ObservationOptions& options,
                                    const Eigen::Matrix3d* R_bi_bj,
                                    const AirframeDescription* airframe) {
  TeammateObservation out;
  out.drone_id = drone_id;
  out.stamp_ns = stamp_ns;
  out.num_points = cluster.num_points;
  const ClusterCentre centre = EstimateCentre(cluster, options, R_bi_bj, airframe);
  out.capture_offset_s = centre.time_offset_s;
  Eigen::Vector3d p = centre.p_in_b;
  if (options.compensate_target_motion) p -= v_bj_in_bi * centre.time_offset_s;
  out.p_bj_in_bi = p;
  out.covariance_m2 = ObservationCovariance(p, options);
  if (airframe != nullptr) {
    out.covariance_m2.diagonal().array() += airframe->centroid_sigma_m * airframe->centroid_sigma_m;
  }
  return out;
}

}  // namespace swarmlio::teammate
