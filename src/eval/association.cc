#include "swarmlio/eval/association.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace swarmlio::eval {

namespace {

/// Index of the stamp in `sorted_s` (non-decreasing) nearest to t_s; of
/// equally near stamps the first. Subtraction is monotone under rounding, so
/// the nearest stamp is one of the two around the insertion point; this
/// equals numpy's argmin(|sorted_s - t_s|).
size_t NearestStamp(const std::vector<double>& sorted_s, double t_s) {
  const auto upper = std::lower_bound(sorted_s.begin(), sorted_s.end(), t_s);
  size_t best = static_cast<size_t>(upper - sorted_s.begin());
  if (best == sorted_s.size()) {
    best = sorted_s.size() - 1;
  } else if (best > 0 && std::abs(sorted_s[best - 1] - t_s) <= std::abs(sorted_s[best] - t_s)) {
    best = best - 1;
  }
  // The first of a run of equal stamps.
  while (best > 0 && sorted_s[best - 1] == sorted_s[best]) --best;
  return best;
}

}  // namespace

Status AssociateTrajectories(const Trajectory& reference,
                             const Trajectory& estimate,
                             const TrajectoryAssociationOptions& options,
                             AssociatedTrajectories* result) {
  if (!std::isfinite(options.max_time_diff_s) || options.max_time_diff_s < 0.0) {
    return Status::InvalidArgument("association: max_time_diff_s must be finite and >= 0, got " +
                                   std::to_string(options.max_time_diff_s));
  }
  if (!std::isfinite(options.time_offset_s)) {
    return Status::InvalidArgument("association: time_offset_s is not finite");
  }
  if (reference.empty()) return Status::InvalidArgument("association: the reference is empty");
  if (estimate.empty()) return Status::InvalidArgument("association: the estimate is empty");
  SWARMLIO_RETURN_IF_ERROR(ValidateTrajectory(reference, "reference"));
  SWARMLIO_RETURN_IF_ERROR(ValidateTrajectory(estimate, "estimate"));

  AssociatedTrajectories out;
  if (!reference.has_stamps() || !estimate.has_stamps()) {
    if (reference.size() != estimate.size()) {
      return Status::InvalidArgument(
          "association: without stamps on both trajectories poses are paired by index, but the "
          "reference has " +
          std::to_string(reference.size()) + " poses and the estimate " +
          std::to_string(estimate.size()));
    }
    for (size_t i = 0; i < reference.size(); ++i) {
      out.reference_ids.push_back(i);
      out.estimate_ids.push_back(i);
    }
    out.max_pairs = reference.size();
  } else {
    // Match the shorter trajectory into the longer one (the estimate into the
    // reference when both have the same size). As in evo, the offset shifts
    // the longer trajectory's stamps: +offset for the estimate, -offset for
    // the reference.
    const bool reference_is_short = reference.size() < estimate.size();
    const std::vector<double>& short_s =
        reference_is_short ? reference.stamps_s : estimate.stamps_s;
    std::vector<double> long_s = reference_is_short ? estimate.stamps_s : reference.stamps_s;
    const double long_shift_s = reference_is_short ? options.time_offset_s : -options.time_offset_s;
    for (double& stamp_s : long_s) stamp_s += long_shift_s;
    std::vector<size_t>& short_ids = reference_is_short ? out.reference_ids : out.estimate_ids;
    std::vector<size_t>& long_ids = reference_is_short ? out.estimate_ids : out.reference_ids;
    for (size_t i = 0; i < short_s.size(); ++i) {
      const size_t j = NearestStamp(long_s, short_s[i]);
      if (std::abs(long_s[j] - short_s[i]) <= options.max_time_diff_s) {
        short_ids.push_back(i);
        long_ids.push_back(j);
      }
    }
    out.max_pairs = short_s.size();
    if (out.reference_ids.empty()) {
      char range[256];
      std::snprintf(range, sizeof(range),
                    "reference stamps [%.6f, %.6f] s, estimate stamps [%.6f, %.6f] s "
                    "(estimate offset %.6f s)",
                    reference.stamps_s.front(), reference.stamps_s.back(),
                    estimate.stamps_s.front(), estimate.stamps_s.back(), options.time_offset_s);
      return Status::FailedPrecondition(
          "association: no matching stamps within max_time_diff_s = " +
          std::to_string(options.max_time_diff_s) + " s; " + range);
    }
  }
  out.reference = reference.Select(out.reference_ids);
  out.estimate = estimate.Select(out.estimate_ids);
  *result = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::eval
