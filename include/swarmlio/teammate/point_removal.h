// Removal of the points on tracked objects before the scan enters the ego
// map (field reference 1.2 step 7: points within 0.7 m of any tracker), so
// that teammates do not leave trails in the map.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/teammate/scan_types.h"

namespace swarmlio::teammate {

/// YAML section `teammate.removal`.
struct PointRemovalOptions {
  double radius_m = 0.7;                  // hard-coded 0.7 m in Swarm-LIO2
  bool around_temporary_trackers = true;  // Swarm-LIO2 removes around every tracker

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("radius_m", radius_m, FieldSpec::AtLeast(0.0, "m", "points this close to a tracker are removed"));
    v("around_temporary_trackers", around_temporary_trackers,
      FieldSpec::Doc("also remove the points around unidentified (temporary) trackers"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// Indices (ascending) of the points within `radius_m` of any centre.
void FindPointsNear(const std::vector<ScanPoint>& points,
                    const std::vector<Eigen::Vector3d>& centers_in_b, double radius_m,
                    std::vector<int>* indices);

/// Copies the points whose index is not in `removed` (ascending).
std::vector<ScanPoint> RemovePoints(const std::vector<ScanPoint>& points,
                                    const std::vector<int>& removed);

}  // namespace swarmlio::teammate
