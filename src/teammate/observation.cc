#include "swarmlio/teammate/observation.h"

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

ClusterCentre EstimateCentre(const PointCluster& cluster, const ObservationOptions& options) {
  ClusterCentre centre;
  if (cluster.num_reflective_points >= options.min_reflective_points) {
    centre.p_in_b = cluster.reflective_centroid_in_b;
    centre.time_offset_s = cluster.reflective_mean_time_offset_s;
  } else {
    centre.p_in_b = cluster.centroid_in_b;
    centre.time_offset_s = cluster.mean_time_offset_s;
  }
  const double range = centre.p_in_b.norm();
  if (range > 0.0) centre.p_in_b += options.centroid_depth_offset_m * centre.p_in_b / range;
  return centre;
}

TeammateObservation MakeObservation(int drone_id, double stamp_s, const PointCluster& cluster,
                                    const Eigen::Vector3d& v_bj_in_bi,
                                    const ObservationOptions& options) {
  TeammateObservation out;
  out.drone_id = drone_id;
  out.stamp_s = stamp_s;
  out.num_points = cluster.num_points;
  const ClusterCentre centre = EstimateCentre(cluster, options);
  out.capture_offset_s = centre.time_offset_s;
  Eigen::Vector3d p = centre.p_in_b;
  if (options.compensate_target_motion) p -= v_bj_in_bi * centre.time_offset_s;
  out.p_bj_in_bi = p;
  out.covariance_m2 = ObservationCovariance(p, options);
  return out;
}

}  // namespace swarmlio::teammate
