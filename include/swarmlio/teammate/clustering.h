// Drone detection in one scan (paper Sec. III-C-1, Alg. 1 lines 1-2):
// reflectivity filtering, Euclidean clustering of the high-reflectivity
// points, and re-clustering of the raw points inside a predicted region.
//
// The points are filtered and cropped in plain Eigen; only the small sets that
// survive (tape returns, a predicted region) go through PCL's
// EuclideanClusterExtraction. PCL stays inside src/teammate.
#pragma once

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/teammate/scan_types.h"

namespace swarmlio::teammate {

/// YAML section `teammate.clustering`. Defaults: Swarm-LIO2 simulation.yaml
/// and the constants MultiUAV.cpp hard-codes (field reference 1.2, 1.4).
struct ClusteringOptions {
  double min_reflectivity = 200.0;  // inten_threshold (240 on real Livox, 200 in simulation)
  double min_range_m = 0.3;         // closer points are ignored (own airframe) [m]
  double max_range_m = 20.0;        // clustering range (hard-coded 20 m) [m]
  double cluster_tolerance_m = 0.3; // Euclidean clustering tolerance [m]
  int min_cluster_points = 3;       // min_high_inten_cluster_size (simulation: 3)
  int max_cluster_points = 1000;    // reflective clustering cap (hard-coded 1000)
  int max_region_points = 150;      // points kept in a predicted region (hard-coded 150)
  double max_object_size_m = 0.6;   // valid_cluster_size_thresh: bounding-box diagonal [m]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("min_reflectivity", min_reflectivity,
      FieldSpec::InRange(0.0, 255.0, "", "reflectivity threshold calibrated on the tape (Livox 0-255)"));
    v("max_object_size_m", max_object_size_m,
      FieldSpec::Positive("m", "clusters with a larger bounding-box diagonal are not drones"));
    config::VisitExperimental(v, [&](auto& x) {
      x("min_range_m", min_range_m, FieldSpec::AtLeast(0.0, "m", "closer points are ignored"));
      x("max_range_m", max_range_m, FieldSpec::Positive("m", "farther points are not clustered"));
      x("cluster_tolerance_m", cluster_tolerance_m,
        FieldSpec::Positive("m", "Euclidean clustering distance tolerance").WithMax(5.0));
      x("min_cluster_points", min_cluster_points,
        FieldSpec::InRange(1.0, 1e6, "", "smallest cluster kept"));
      x("max_cluster_points", max_cluster_points,
        FieldSpec::InRange(1.0, 1e7, "", "largest reflective cluster kept"));
      x("max_region_points", max_region_points,
        FieldSpec::InRange(1.0, 1e6, "", "nearest raw points kept in a predicted region"));
    });
  }
  std::string Validate() const {
    std::string error = config::ValidateFields(*this);
    if (!error.empty()) return error;
    std::ostringstream os;
    if (!(min_range_m < max_range_m)) {
      os << "min_range_m: must be below max_range_m (" << min_range_m << " >= " << max_range_m << ")";
    } else if (min_cluster_points > max_cluster_points) {
      os << "min_cluster_points: must not exceed max_cluster_points (" << min_cluster_points
         << " > " << max_cluster_points << ")";
    }
    return os.str();
  }
};

/// Reflectivity filtering and Euclidean clustering. Reuses its buffers, so
/// one instance per thread.
class ReflectiveClusterer {
 public:
  explicit ReflectiveClusterer(const ClusteringOptions& options);
  ~ReflectiveClusterer();
  ReflectiveClusterer(const ReflectiveClusterer&) = delete;
  ReflectiveClusterer& operator=(const ReflectiveClusterer&) = delete;

  const ClusteringOptions& options() const { return options_; }
  /// Moves the two gates a teammate's announced airframe widens
  /// (TeammateDetector::SetTeammateAirframe); both must be finite and the
  /// size positive.
  void SetGates(double min_reflectivity, double max_object_size_m) {
    options_.min_reflectivity = min_reflectivity;
    options_.max_object_size_m = max_object_size_m;
  }

  /// True if a cluster's size is plausible for a drone.
  bool IsDroneSized(const PointCluster& cluster) const {
    return cluster.SizeM() <= options_.max_object_size_m;
  }

  /// Points with reflectivity >= min_reflectivity within [min_range_m,
  /// max_range_m], clustered. Returns every cluster of at least
  /// min_cluster_points (size not tested). `num_reflective_points` (optional)
  /// receives the number of points that passed the filter.
  void FindReflectiveClusters(const std::vector<ScanPoint>& points,
                              std::vector<PointCluster>* clusters,
                              int* num_reflective_points = nullptr);

  /// Re-clustering in a predicted region: the raw points (any reflectivity)
  /// within `radius_m` of `center_in_b` (at most max_region_points, the
  /// nearest ones) are clustered; the cluster whose centroid is closest to the
  /// centre is returned. False when the region holds no cluster.
  bool ClusterRegion(const std::vector<ScanPoint>& points, const Eigen::Vector3d& center_in_b,
                     double radius_m, PointCluster* cluster);

  /// Clusters the points `indices` of `points` (plain Euclidean clustering
  /// with the options' tolerance and size limits).
  void ClusterIndices(const std::vector<ScanPoint>& points, const std::vector<int>& indices,
                      int max_cluster_points, std::vector<PointCluster>* clusters);

 private:
  struct Impl;
  ClusteringOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::teammate
