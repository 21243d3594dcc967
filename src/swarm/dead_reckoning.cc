#include "dead_reckoning.h"

#include <algorithm>

namespace swarmlio::swarm::internal {

void DeadReckoningTrack::Append(const std::vector<ImuPose>& poses, double keep_s) {
  if (poses.empty()) return;
  if (track_.empty() || track_.back().first > poses.front().stamp_ns) {
    track_.clear();  // first scan, or time went back (a new log): start over
    track_.emplace_back(poses.front().stamp_ns, Eigen::Vector3d::Zero());
  }
  for (size_t k = 1; k < poses.size(); ++k) {
    if (poses[k].stamp_ns <= track_.back().first) continue;
    track_.emplace_back(poses[k].stamp_ns,
                        track_.back().second + poses[k].p_b_in_G - poses[k - 1].p_b_in_G);
  }
  const int64_t keep_ns = static_cast<int64_t>(keep_s * 1e9);
  const int64_t newest = track_.back().first;
  while (track_.size() > 2 && track_[1].first < newest - keep_ns) track_.pop_front();
}

Eigen::Vector3d DeadReckoningTrack::At(int64_t t_ns) const {
  const auto it = std::lower_bound(
      track_.begin(), track_.end(), t_ns,
      [](const std::pair<int64_t, Eigen::Vector3d>& e, int64_t t) { return e.first < t; });
  if (it == track_.begin()) return it->second;
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double u = static_cast<double>(t_ns - a.first) / static_cast<double>(b.first - a.first);
  return a.second + u * (b.second - a.second);
}

bool DeadReckoningTrack::Displacement(int64_t t_j_ns, int64_t t_k_ns,
                                      Eigen::Vector3d* displacement) const {
  if (track_.size() < 2 || t_j_ns > t_k_ns || t_j_ns < track_.front().first ||
      t_k_ns > track_.back().first) {
    return false;
  }
  *displacement = At(t_j_ns) - At(t_k_ns);
  return true;
}

}  // namespace swarmlio::swarm::internal
