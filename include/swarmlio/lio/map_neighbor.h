// Neighbor: one result of a nearest-neighbour query on the local map.
#pragma once

#include <Eigen/Core>

namespace swarmlio::lio {

struct Neighbor {
  Eigen::Vector3d point_in_G = Eigen::Vector3d::Zero();  // map point, global frame [m]
  double squared_distance_m2 = 0.0;                      // to the query [m^2]
  double observed_range_m = 0.0;  // LiDAR range it was observed from (0 = unknown) [m]
};

}  // namespace swarmlio::lio
