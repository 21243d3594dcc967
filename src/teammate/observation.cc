#include "swarmlio/teammate/observation.h"

#include <cmath>

namespace swarmlio::teammate {
namespace {

// A tape band of half extents a (x) and b (y) around the body origin.
AirframeDescription BandOf(double a, double b) {
  AirframeDescription band;
  band.reflector_shape = ReflectorShape::kBand;
  band.reflector_half_extents_m.x() = a;
  band.reflector_half_extents_m.y() = b;
  band.reflector_centre_in_body_m.setZero();
  return band;
}

}  // namespace

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
  return VisibleReflectorCentroid(BandOf(a, b), u_in_bj);
}

ClusterCentre EstimateCentre(const PointCluster& cluster,
                             const ObservationOptions& options,
                             const Eigen::Matrix3d* R_bi_bj,
                             const AirframeDescription* airframe) {
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
  // The teammate's announced body, else the options' band (when configured).
  const AirframeDescription options_band =
      BandOf(options.tape_half_length_m, options.tape_half_width_m);
  const AirframeDescription* body =
      airframe != nullptr ? airframe : (options.UsesTapeBand() ? &options_band : nullptr);
  if (tape_only && body != nullptr && R_bi_bj != nullptr) {
    const Eigen::Vector3d u_in_bj = R_bi_bj->transpose() * (-centre.p_in_b / range);
    centre.p_in_b -=
        *R_bi_bj * (body->reflector_centre_in_body_m + VisibleReflectorCentroid(*body, u_in_bj));
  } else {
    centre.p_in_b += options.centroid_depth_offset_m * centre.p_in_b / range;
  }
  return centre;
}

TeammateObservation MakeObservation(int drone_id,
                                    int64_t stamp_ns,
                                    const PointCluster& cluster,
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
