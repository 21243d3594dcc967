// FitPlane: a local plane n^T q + d = 0 through the k nearest map neighbours
// of a scan point, for the point-to-plane residual z = n^T (R_G_b p_b + p_b_in_G) + d
// (paper eq. (4)).
//
// Method: PCA. The normal n is the eigenvector of the smallest eigenvalue of
// the neighbours' scatter matrix about their centroid c, and d = -n^T c. This
// is the total-least-squares plane (minimises the sum of squared orthogonal
// distances). FAST-LIO instead solves A n' = -1 in least squares (the plane
// n'^T q + 1 = 0), which cannot represent a plane through the origin of G and
// minimises an algebraic, not geometric, error; PCA has neither problem and
// costs one 3x3 closed-form eigen decomposition.
//
// Acceptance, in this order (the status names the first failed test):
//   kTooFewPoints:    fewer than min_neighbors neighbours;
//   kNeighborsTooFar: the farthest neighbour's squared distance to the query
//                     exceeds max_neighbor_sq_distance_m2 (FAST-LIO: 5th-NN
//                     squared distance > 5 m^2 -> no match);
//   kDegenerate:      the neighbours lie on a line or a point (in-plane spread
//                     sqrt(lambda_mid) < min_plane_extent_m), normal undefined;
//   kNotPlanar:       some neighbour is farther than max_point_to_plane_m from
//                     the plane (FAST-LIO esti_plane threshold 0.1 m).
// Normal uncertainty (reported, not a test; the scan association uses it):
// each neighbour's noise along the normal is taken as
//   sigma_i^2 = map_range_stddev^2 + (r_i map_angular_stddev)^2,
// r_i the range it was observed from (Neighbor::observed_range_m; at grazing
// incidence a beam-direction error moves the point along the normal by
// range x angle), and the fitted normal tilts about the plane's narrower
// in-plane axis (it moves n along tilt_axis_in_G, the narrower in-plane axis)
// with stddev sigma_n = sqrt(mean_i sigma_i^2 / (k lambda_mid)), the
// least-squares slope error (docs/lio.md, "Noisy map planes").
// Orientation: n is a unit vector with d <= 0 (the origin of G lies on the
// negative side; for d == 0 the first non-zero component of n is positive),
// so the same neighbours always give the same (n, d).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/lio/map_neighbor.h"

namespace swarmlio::lio {

struct PlaneFitOptions {
  int min_neighbors = 5;                      // NUM_MATCH_POINTS
  double max_neighbor_sq_distance_m2 = 5.0;   // farthest neighbour to the query [m^2]
  double max_point_to_plane_m = 0.1;          // planarity: every neighbour within [m]
  double min_plane_extent_m = 0.01;           // sqrt of the middle scatter eigenvalue [m]
  double map_range_stddev_m = 0.02;     // range noise of the map points, 1 sigma [m]
  double map_angular_stddev_deg = 0.0;  // LiDAR angular precision, 1 sigma [deg]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("min_neighbors", min_neighbors,
      FieldSpec::InRange(3.0, 100.0, "", "neighbours needed for a plane (NUM_MATCH_POINTS)"));
    v("max_neighbor_sq_distance_m2", max_neighbor_sq_distance_m2,
      FieldSpec::Positive("m^2", "reject when the farthest neighbour's squared distance to the "
                                 "query exceeds this"));
    v("max_point_to_plane_m", max_point_to_plane_m,
      FieldSpec::Positive("m", "every neighbour must be this close to the plane"));
    v("min_plane_extent_m", min_plane_extent_m,
      FieldSpec::AtLeast(0.0, "m", "reject collinear neighbours (in-plane RMS spread below)"));
    v("map_range_stddev_m", map_range_stddev_m,
      FieldSpec::AtLeast(0.0, "m", "range noise of the map points (1 sigma)"));
    v("map_angular_stddev_deg", map_angular_stddev_deg,
      FieldSpec::InRange(0.0, 10.0, "deg", "angular precision of the LiDAR (1 sigma)"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

enum class PlaneFitStatus { kOk, kTooFewPoints, kNeighborsTooFar, kDegenerate, kNotPlanar };

const char* ToString(PlaneFitStatus status);

struct Plane {
  Eigen::Vector3d normal_in_G = Eigen::Vector3d::UnitZ();  // unit normal n
  double offset_m = 0.0;                 // d: n^T q + d = 0 for q on the plane [m]
  double max_abs_residual_m = 0.0;       // max_i |n^T q_i + d| over the neighbours [m]
  double rms_residual_m = 0.0;           // RMS of n^T q_i + d [m]
  double curvature = 0.0;  // lambda_min / (sum of eigenvalues), 0 = flat, 1/3 = isotropic
  double normal_stddev_rad = 0.0;  // sigma_n: modelled tilt stddev of n (above) [rad]
  // Unit in-plane axis along which the uncertain tilt moves n (the scatter's
  // middle eigenvector: the plane's narrower in-plane extent).
  Eigen::Vector3d tilt_axis_in_G = Eigen::Vector3d::UnitX();
  // Tilt stddev of n toward the other in-plane axis (the scatter's largest
  // eigenvector, tilt_axis_in_G x normal_in_G up to sign): the same formula
  // with lambda_max [rad].
  double normal_stddev_major_rad = 0.0;
  Eigen::Vector3d centroid_in_G = Eigen::Vector3d::Zero();  // mean of the neighbours [m]

  /// Modelled stddev of n^T e, the normal's tilt toward the unit vector `e`
  /// (both in-plane axes) [rad].
  double TiltStddevToward(const Eigen::Vector3d& e) const;

  /// Signed distance of `q_in_G` to the plane [m].
  double SignedDistance(const Eigen::Vector3d& q_in_G) const {
    return normal_in_G.dot(q_in_G) + offset_m;
  }
};

/// Fits a plane to `points`; `farthest_sq_distance_m2` is the largest squared
/// distance of a neighbour to the query. `*plane` is written on kOk only.
PlaneFitStatus FitPlane(const std::vector<Eigen::Vector3d>& points,
                        double farthest_sq_distance_m2, const PlaneFitOptions& options,
                        Plane* plane);

/// Same, from LocalMap::KNearest results.
PlaneFitStatus FitPlane(const std::vector<Neighbor>& neighbors, const PlaneFitOptions& options,
                        Plane* plane);

}  // namespace swarmlio::lio
