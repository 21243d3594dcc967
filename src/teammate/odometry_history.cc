#include "swarmlio/teammate/odometry_history.h"

#include "swarmlio/common/time.h"

#include <algorithm>
#include <cmath>

namespace swarmlio::teammate {

void OdometryHistory::Add(const TeammateOdometry& odometry, double keep_s) {
  auto it = std::lower_bound(
      messages_.begin(), messages_.end(), odometry.stamp_ns,
      [](const TeammateOdometry& m, int64_t stamp_ns) { return m.stamp_ns < stamp_ns; });
  if (it != messages_.end() && it->stamp_ns == odometry.stamp_ns) {
    *it = odometry;
  } else {
    messages_.insert(it, odometry);
  }
  const int64_t oldest_kept = messages_.back().stamp_ns - ToNanoseconds(keep_s);
  while (!messages_.empty() && messages_.front().stamp_ns < oldest_kept) messages_.pop_front();
}

bool OdometryHistory::StateAt(int64_t stamp_ns, double max_gap_s, double max_extrapolation_s,
                              Eigen::Vector3d* p_bj_in_Gj, Eigen::Vector3d* v_bj_in_Gj) const {
  if (messages_.empty()) return false;
  auto after = std::lower_bound(
      messages_.begin(), messages_.end(), stamp_ns,
      [](const TeammateOdometry& m, int64_t s) { return m.stamp_ns < s; });
  if (after != messages_.end() && after != messages_.begin()) {
    const TeammateOdometry& a = *(after - 1);
    const TeammateOdometry& b = *after;
    const double h = SecondsBetween(a.stamp_ns, b.stamp_ns);
    if (h <= max_gap_s && h > 0.0) {
      // Cubic Hermite on [a, b] with the broadcast velocities as tangents.
      const double s = SecondsBetween(a.stamp_ns, stamp_ns) / h;
      const double s2 = s * s, s3 = s2 * s;
      const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
      const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      *p_bj_in_Gj = h00 * a.p_bj_in_Gj + h10 * h * a.v_bj_in_Gj + h01 * b.p_bj_in_Gj +
                    h11 * h * b.v_bj_in_Gj;
      if (v_bj_in_Gj != nullptr) *v_bj_in_Gj = (1.0 - s) * a.v_bj_in_Gj + s * b.v_bj_in_Gj;
      return true;
    }
  }
  // Nearest message, extrapolated with its velocity.
  const TeammateOdometry* nearest = Nearest(stamp_ns);
  const double dt = SecondsBetween(nearest->stamp_ns, stamp_ns);
  if (std::abs(dt) > max_extrapolation_s) return false;
  *p_bj_in_Gj = nearest->p_bj_in_Gj + nearest->v_bj_in_Gj * dt;
  if (v_bj_in_Gj != nullptr) *v_bj_in_Gj = nearest->v_bj_in_Gj;
  return true;
}

const TeammateOdometry* OdometryHistory::Nearest(int64_t stamp_ns) const {
  if (messages_.empty()) return nullptr;
  auto after = std::lower_bound(
      messages_.begin(), messages_.end(), stamp_ns,
      [](const TeammateOdometry& m, int64_t s) { return m.stamp_ns < s; });
  const TeammateOdometry* nearest = after != messages_.end() ? &*after : nullptr;
  if (after != messages_.begin()) {
    const TeammateOdometry& before = *(after - 1);
    if (nearest == nullptr ||
        std::abs(before.stamp_ns - stamp_ns) < std::abs(nearest->stamp_ns - stamp_ns)) {
      nearest = &before;
    }
  }
  return nearest;
}

bool OdometryHistory::AttitudeAt(int64_t stamp_ns, double max_age_s,
                                 Eigen::Quaterniond* q_Gj_bj) const {
  const TeammateOdometry* nearest = Nearest(stamp_ns);
  if (nearest == nullptr || std::abs(SecondsBetween(stamp_ns, nearest->stamp_ns)) > max_age_s) return false;
  *q_Gj_bj = nearest->q_Gj_bj;
  return true;
}

}  // namespace swarmlio::teammate
