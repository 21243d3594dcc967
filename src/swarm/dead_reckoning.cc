#include "dead_reckoning.h"

#include <algorithm>

#include "swarmlio/common/time.h"

namespace swarmlio::swarm::internal {

void DeadReckoningTrack::Append(const std::vector<lio::ImuPose>& poses, double keep_s) {
  if (poses.size() < 2) return;
  // Time going back (a new log) or a gap of more than 50 ms (dropped scans):
  // start over, so the history stays contiguous; a shorter gap is bridged
  // with the first new acceleration.
  if (!segments_.empty()) {
    const int64_t gap_ns = poses.front().stamp_ns - segments_.back().end_ns;
    if (gap_ns < 0 || gap_ns > 50'000'000) {
      segments_.clear();
    } else if (gap_ns > 0) {
      segments_.push_back({segments_.back().end_ns, poses.front().stamp_ns,
                           poses.front().acc_in_G_m_s2, poses.front().R_G_b});
    }
  }
  for (size_t k = 0; k + 1 < poses.size(); ++k) {
    if (poses[k + 1].stamp_ns <= poses[k].stamp_ns) continue;
    segments_.push_back(
        {poses[k].stamp_ns, poses[k + 1].stamp_ns, poses[k].acc_in_G_m_s2, poses[k].R_G_b});
  }
  if (segments_.empty()) return;
  const int64_t keep_ns = ToNanoseconds(keep_s);
  const int64_t newest = segments_.back().end_ns;
  while (segments_.size() > 1 && segments_.front().end_ns < newest - keep_ns) {
    segments_.pop_front();
  }
}

bool DeadReckoningTrack::Retrodiction(int64_t t_j_ns, int64_t t_k_ns,
                                      ImuRetrodiction* r) const {
  if (segments_.empty() || t_j_ns > t_k_ns || t_j_ns < segments_.front().begin_ns ||
      t_k_ns > segments_.back().end_ns) {
    return false;
  }
  // First segment ending after t_j.
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t_j_ns,
                             [](int64_t t, const Segment& s) { return t < s.end_ns; });
  ImuRetrodiction sum;
  for (; it != segments_.end() && it->begin_ns < t_k_ns; ++it) {
    // int_a^b (s - t_j) ds over the part of the segment inside [t_j, t_k].
    const double a = SecondsBetween(t_j_ns, std::max(it->begin_ns, t_j_ns));
    const double b = SecondsBetween(t_j_ns, std::min(it->end_ns, t_k_ns));
    const double w = 0.5 * (b * b - a * a);
    sum.weight_s2 += w;
    sum.weighted_acc_in_G += w * it->acc_in_G;
    sum.weighted_R_G_b += w * it->R_G_b;
  }
  *r = sum;
  return true;
}

}  // namespace swarmlio::swarm::internal
