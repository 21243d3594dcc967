#include "src/lio/back_end.h"

namespace swarmlio::lio::internal {

int InsertScan(const std::vector<Eigen::Vector3d>& points_in_b, const EgoState& x,
               const std::vector<ExcludedRegion>& excluded,
               std::vector<Eigen::Vector3d>* registered_out,
               const std::vector<int>* skip_indices, LocalMap* map) {
  const Eigen::Matrix3d R_G_b = x.q_G_b.toRotationMatrix();
  std::vector<Eigen::Vector3d> registered;
  std::vector<double> ranges;  // from the body origin: the LiDAR's within its lever arm
  registered.reserve(points_in_b.size());
  ranges.reserve(points_in_b.size());
  if (registered_out != nullptr) registered_out->clear();
  std::vector<bool> skip;
  if (skip_indices != nullptr) {
    skip.assign(points_in_b.size(), false);
    for (int i : *skip_indices) {
      if (i >= 0 && static_cast<size_t>(i) < skip.size()) skip[static_cast<size_t>(i)] = true;
    }
  }
  int num_excluded = 0;
  for (size_t i = 0; i < points_in_b.size(); ++i) {
    const Eigen::Vector3d& p = points_in_b[i];
    bool inside = false;
    for (const ExcludedRegion& region : excluded) {
      inside |= (p - region.center_in_b).squaredNorm() <= region.radius_m * region.radius_m;
    }
    if (inside) {
      ++num_excluded;
      continue;
    }
    const Eigen::Vector3d q = R_G_b * p + x.p_b_in_G;
    if (registered_out != nullptr) registered_out->push_back(q);
    if (!skip.empty() && skip[i]) continue;
    registered.push_back(q);
    ranges.push_back(p.norm());
  }
  map->UpdateCenter(x.p_b_in_G);
  map->Insert(registered, &ranges);
  return num_excluded;
}

bool IsFinite(const SwarmState& x, const Eigen::MatrixXd& P) {
  return x.ego.q_G_b.coeffs().allFinite() && x.ego.p_b_in_G.allFinite() &&
         x.ego.v_b_in_G.allFinite() && x.ego.gyro_bias.allFinite() &&
         x.ego.accel_bias.allFinite() && x.ego.g_in_G.allFinite() && P.allFinite();
}

}  // namespace swarmlio::lio::internal
