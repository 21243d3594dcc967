// Data association of clusters to tracker predictions (field reference 1.2
// step 4): each tracker takes the nearest free cluster within its gate; a
// taken cluster is no longer a candidate. Pairs are assigned globally
// nearest-first, so the result does not depend on the tracker order.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::teammate {

/// Association of clusters to tracker predictions; YAML section
/// `teammate.experimental.association`. Defaults: Swarm-LIO2 (field reference
/// 1.2, 1.4; simulation.yaml where it differs from the code).
struct TrackAssociationOptions {
  double teammate_gate_m = 0.3;            // valid_cluster_dist_thresh (0.2 Mid-360 .. 0.6 sim)
  double temporary_gate_m = 0.8;           // valid_temp_cluster_dist_thresh (0.4; 0.8 in sim)
  bool recluster_in_predicted_region = true;  // cluster_extraction_in_predict_region
  double teammate_region_radius_m = 0.5;   // predict_region_radius
  double temporary_region_radius_m = 0.5;  // temp_predict_region_radius
  double same_object_m = 0.5;              // same_obj_thresh: a cluster this close to a tracker is not new

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("teammate_gate_m", teammate_gate_m,
      FieldSpec::Positive("m", "largest cluster-to-prediction distance for a teammate tracker"));
    v("temporary_gate_m", temporary_gate_m,
      FieldSpec::Positive("m", "largest cluster-to-prediction distance for a temporary tracker"));
    v("recluster_in_predicted_region", recluster_in_predicted_region,
      FieldSpec::Doc("re-cluster the raw points around a prediction when the gate fails"));
    v("teammate_region_radius_m", teammate_region_radius_m,
      FieldSpec::Positive("m", "radius of a teammate tracker's predicted region"));
    v("temporary_region_radius_m", temporary_region_radius_m,
      FieldSpec::Positive("m", "radius of a temporary tracker's predicted region"));
    v("same_object_m", same_object_m,
      FieldSpec::AtLeast(0.0, "m", "an unassociated cluster this close to a tracker starts none"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// For each prediction, the index of its cluster or -1. Only clusters with
/// `available[k]` are candidates; assigned clusters are marked unavailable.
std::vector<int> AssociateNearest(const std::vector<Eigen::Vector3d>& predictions,
                                  const std::vector<Eigen::Vector3d>& clusters, double gate_m,
                                  std::vector<bool>* available);

}  // namespace swarmlio::teammate
