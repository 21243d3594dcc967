// ScanAssociator: the plane correspondences of one undistorted scan against
// the local map at a state estimate (paper eq. (4); the association callback
// of EsikfUpdate).
//
// For each scan point p (body frame at the scan end) at the estimate
// (R_G_b, p_b_in_G): q = R_G_b p + p_b_in_G; its k nearest map points give a
// plane (FitPlane, PCA with the planarity test); the correspondence is kept
// when the point is close to the plane relative to its range, FAST-LIO's
// gate  |n^T q + d| < residual_gate_factor * sqrt(|p|)  (FAST-LIO:
// 1 - 0.9 |z| / sqrt(|p|) > 0.9, i.e. factor 1/9). Weight 1 / sigma^2 with
// sigma = point_stddev_m (an effective value, see the option).
//
// Re-association at every outer iteration: the gate and the residual are
// re-evaluated at each estimate; the nearest-neighbour search (the expensive
// part) is repeated for a point only when its position in G moved more than
// research_distance_m since its last search (FAST-LIO searches at the first
// iteration and after convergence only). With research_distance_m = 0 every
// iteration searches every point. The searches and plane fits may run on
// several threads (ParallelFor); the gate, the counts and the list are made
// after them in point order, so the result does not depend on the threads.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "factors/point_to_plane_factor.h"
#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/parallel_for.h"
#include "swarmlio/lio/plane_fit.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

/// Plane-fit defaults for scan association, stricter than FAST-LIO's (0.1 m
/// planarity, 5 m^2 neighbour reach, no collinearity or normal-uncertainty
/// test): with sparse maps
/// (one Livox Avia scan) looser planes tilted the attitude by ~0.4-1 deg while
/// static (docs/lio.md, "Plane acceptance").
inline PlaneFitOptions AssociationPlaneFitDefaults() {
  PlaneFitOptions options;
  options.max_point_to_plane_m = 0.05;
  options.min_plane_extent_m = 0.05;
  options.max_neighbor_sq_distance_m2 = 1.0;
  return options;
}

/// Association of scan points to local-map planes (ScanAssociator); YAML section
/// `odometry.experimental.association`.
struct ScanAssociationOptions {
  int num_neighbors = 5;                 // k of the plane fit (NUM_MATCH_POINTS)
  // Effective sigma of z [m]: sensor noise plus map / plane-fit errors, which
  // are shared by neighbouring points (correlated), so far above the range
  // noise. FAST-LIO's LASER_POINT_COV (0.001 m^2, 0.0316 m) makes the filter
  // overconfident: position NEES 14-430 on indoor_3uav vs 0.7-2.8 with 0.12 m
  // on the ideal simulator (docs/lio.md, "Consistency"). Tuned on the
  // realistic simulator (indoor_3uav, seed 1, swarm mode): 0.12 m gave NEES
  // 5.9 / 12.4 / 4.8, 0.15 m 4.1 / 8.4 / 4.3, 0.18 m 3.1 / 6.2 / 3.2, 0.22 m
  // 2.3 / 4.4 / 2.6 (expected 3) at unchanged APE up to 0.18 m.
  double point_stddev_m = 0.18;
  double residual_gate_factor = 1.0 / 9.0;  // keep |z| < factor * sqrt(|p_b|) [sqrt(m)]
  double research_distance_m = 0.05;     // re-search neighbours after moving this far [m]
  // A scan is flagged degenerate when the smallest eigenvalue of
  // sum_n n_n n_n^T over its correspondences is below this (Swarm-LIO2
  // degeneration_thresh: code default 30, 10 in its Mid-360 config) [-].
  double degeneracy_threshold = 30.0;
  // Noisy map planes (docs/lio.md): a plane whose normal may tilt by sigma_n
  // (PlaneFitOptions' noise model) about its narrower in-plane axis u adds
  // spurious information sigma_n^2 u u^T. Along an eigen-direction e of
  // I = sum n n^T where I is below spurious_information_ratio times the
  // expected spurious sum_n sigma_n^2 (u_n^T e)^2, the planes with
  // sigma_n |u_n^T e| > max_normal_stddev_rad are dropped (a corridor's
  // axis); elsewhere every plane is kept (far planes are the only
  // information in open spaces). The ratio is large because the model
  // under-counts: the planarity test keeps the fits whose tilt absorbed the
  // noise, and neighbouring planes share map points. Chosen on the tuning
  // set {indoor_3uav seed 1, corridor seed 3, exploration seed 4}; 0 = off.
  double max_normal_stddev_rad = 0.2;
  double spurious_information_ratio = 30.0;
  // Along such a direction e, each kept plane's lean l = n^T e shrinks to
  // sqrt(max(0, l^2 - (k t_e)^2)), k = tilt_projection_sigma and t_e =
  // Plane::TiltStddevToward(e): a plane parallel to e within k sigma is
  // projected onto e's complement, a real lean keeps what noise cannot
  // explain; the plane then passes through its neighbours' centroid. It keeps
  // its information across e. A normal that would lose more than half its
  // length is dropped (docs/lio.md "Noisy map planes"); 0 = off.
  double tilt_projection_sigma = 3.0;
  PlaneFitOptions plane = AssociationPlaneFitDefaults();

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("num_neighbors", num_neighbors,
      FieldSpec::InRange(3.0, 50.0, "", "map neighbours per plane (NUM_MATCH_POINTS)"));
    v("point_stddev_m", point_stddev_m,
      FieldSpec::Positive("m", "point-to-plane measurement standard deviation"));
    v("residual_gate_factor", residual_gate_factor,
      FieldSpec::Positive("m^0.5", "keep |z| < factor * sqrt(range); FAST-LIO 1/9"));
    v("research_distance_m", research_distance_m,
      FieldSpec::AtLeast(0.0, "m",
                         "repeat a point's neighbour search when it moved this far; 0 = always"));
    v("max_normal_stddev_rad", max_normal_stddev_rad,
      FieldSpec::AtLeast(0.0, "rad",
                         "along noise-dominated directions drop planes whose normal's tilt "
                         "toward them exceeds this; 0 = off"));
    v("spurious_information_ratio", spurious_information_ratio,
      FieldSpec::AtLeast(1.0, "",
                         "a direction is noise-dominated when its plane information is below "
                         "this times the information normal tilt noise alone would give"));
    v("tilt_projection_sigma", tilt_projection_sigma,
      FieldSpec::AtLeast(0.0, "",
                         "along noise-dominated directions project out normals leaning toward "
                         "them by less than this many modelled tilt stddevs; 0 = off"));
    v("degeneracy_threshold", degeneracy_threshold,
      FieldSpec::AtLeast(0.0, "", "degenerate scan: smallest eigenvalue of sum n n^T below this"));
    v("plane", plane);
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

struct AssociationStats {
  int num_points = 0;
  int num_searched = 0;       // neighbour searches run in the last call
  int num_no_plane = 0;       // too few / too far neighbours, not planar
  int num_gated = 0;          // plane found, residual too large
  int num_tilt_gated = 0;     // dropped along a noise-dominated direction
  int num_tilt_projected = 0; // normal projected off a noise-dominated direction
  int num_correspondences = 0;
  /// sum_n n_n n_n^T over the correspondences: how well the planes constrain
  /// the translation in each direction (see MinNormalInformation()).
  Eigen::Matrix3d normal_information = Eigen::Matrix3d::Zero();

  /// Smallest eigenvalue of normal_information (the degeneracy metric).
  double MinNormalInformation() const;
};

class ScanAssociator {
 public:
  /// `map` must outlive the associator and not change while it is in use;
  /// `parallel` (may be null: one thread), when given, runs the neighbour
  /// searches and plane fits and must outlive the associator. The result is
  /// the same for any thread count.
  ScanAssociator(const LocalMap* map, const ScanAssociationOptions& options,
                 const ParallelFor* parallel = nullptr);

  /// Starts a new scan: `points_in_b` (body frame at the scan end) must
  /// outlive the calls to Associate(). Forgets cached neighbours.
  void Reset(const std::vector<Eigen::Vector3d>* points_in_b);

  /// Fills `*out` (cleared) with the correspondences at the estimate `x`.
  Status Associate(const SwarmState& x, std::vector<PlaneCorrespondence>* out);

  /// Statistics of the last Associate() call.
  const AssociationStats& stats() const { return stats_; }

  /// For each correspondence of the last Associate() call, in its order, the
  /// index of its point in the scan given to Reset().
  const std::vector<int>& matched_point_indices() const { return matched_; }

 private:
  struct CachedPlane {
    Eigen::Vector3d searched_at_in_G = Eigen::Vector3d::Constant(1e300);
    bool has_plane = false;
    Plane plane;
  };

  // The noisy-plane rule (ScanAssociationOptions: max_normal_stddev_rad, then
  // tilt_projection_sigma) on `out`, whose planes are planes_: drops and
  // shrinks along noise-dominated directions and counts both. Runs only while
  // max_normal_stddev_rad > 0 (which so switches the whole rule off).
  void ApplyNoisyPlaneRule(std::vector<PlaneCorrespondence>* out);

  // The neighbour search and plane fit of every point that moved more than
  // research_distance_m since its last search (all of them after Reset()),
  // at the estimate (R_G_b, p_b_in_G); marks them in searched_ and leaves
  // every point's position in G in queries_in_G_.
  void SearchMoved(const Eigen::Matrix3d& R_G_b, const Eigen::Vector3d& p_b_in_G);

  const LocalMap* map_;
  ScanAssociationOptions options_;
  const std::vector<Eigen::Vector3d>* points_in_b_ = nullptr;
  std::vector<CachedPlane> cache_;
  const ParallelFor* parallel_ = nullptr;
  std::vector<uint8_t> searched_;     // scratch: 1 where the last call searched
  std::vector<Eigen::Vector3d> queries_in_G_;  // scratch: the points in G at the estimate
  std::vector<const Plane*> planes_;  // scratch: the plane of each correspondence
  std::vector<int> matched_;          // the scan point of each correspondence
  AssociationStats stats_;
};

}  // namespace swarmlio::lio
