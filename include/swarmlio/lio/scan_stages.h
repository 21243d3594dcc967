// What the stages of lio::Odometry's scan pipeline exchange with the
// component that drives them (swarm::DroneEstimator, or
// Odometry::ProcessReadyScans for a single drone). The component calls the
// stages top-down, once per scan:
//
//   odometry.NextScan(flush, &scan)    preprocess, propagate, undistort
//   ... the component's front end: teammate detection on scan.raw with
//       scan.poses, teammate blocks added to / removed from scan.x, scan.P,
//       measurement models built, scan.excluded filled ...
//   odometry.Update(request, &scan)    prior + point-to-plane + the request's
//                                      models (filter or window back end)
//   odometry.Commit(&scan, &output)    map insertion without scan.excluded,
//                                      the scan's output
#pragma once

#include <Eigen/Core>
#include <vector>

#include "swarmlio/lio/measurement_model.h"

namespace swarmlio::lio {

/// A ball in the body frame at the scan end whose points stay out of the map.
struct ExcludedRegion {
  Eigen::Vector3d center_in_b = Eigen::Vector3d::Zero();  // [m]
  double radius_m = 0.0;
};

/// The measurement models a component adds to the scan's update.
struct UpdateRequest {
  std::vector<MeasurementModel*> models;  // not owned; valid until Update returns
  /// true: only `estimated_teammates` are corrected (the other blocks are
  /// held, or considered); false: every teammate block not considered is.
  bool select_teammates = false;
  /// Teammate blocks the update estimates (the others: Schmidt "consider").
  std::vector<int> estimated_teammates;
  /// Teammate blocks the models' residuals name that the update does not
  /// correct (EsikfUpdate::Run, "considered teammates").
  std::vector<int> considered_teammates;
};

}  // namespace swarmlio::lio
