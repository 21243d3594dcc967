#include "swarmlio/lio/undistortion.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "swarmlio/common/check.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

// Index of the pose whose interval holds t (seconds after poses[0]):
// the last pose with t_i <= t, clamped to [0, size - 1].
int IntervalIndex(const std::vector<double>& times_s, double t_s) {
  const auto it = std::upper_bound(times_s.begin(), times_s.end(), t_s);
  if (it == times_s.begin()) return 0;
  return static_cast<int>(it - times_s.begin()) - 1;
}

void PoseInInterval(const ImuPose& pose,
                    double tau_s,
                    Eigen::Matrix3d* R_G_b,
                    Eigen::Vector3d* p_b_in_G) {
  *R_G_b = pose.R_G_b * so3::Exp(pose.angular_velocity_in_b_rad_s * tau_s);
  *p_b_in_G = pose.p_b_in_G + pose.v_b_in_G * tau_s + 0.5 * tau_s * tau_s * pose.acc_in_G_m_s2;
}

std::vector<double> RelativeTimes(const std::vector<ImuPose>& poses) {
  std::vector<double> times_s(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    times_s[i] = ToSeconds(poses[i].stamp_ns - poses.front().stamp_ns);
  }
  return times_s;
}

}  // namespace

void BodyPoseAt(const std::vector<ImuPose>& poses,
                int64_t stamp_ns,
                double offset_s,
                Eigen::Matrix3d* R_G_b,
                Eigen::Vector3d* p_b_in_G) {
  CHECK(!poses.empty());
  const std::vector<double> times_s = RelativeTimes(poses);
  const double t_s = ToSeconds(stamp_ns - poses.front().stamp_ns) + offset_s;
  const int i = IntervalIndex(times_s, t_s);
  PoseInInterval(poses[i], t_s - times_s[i], R_G_b, p_b_in_G);
}

namespace {

Status CheckPoses(const std::vector<ImuPose>& poses, int64_t scan_stamp_ns) {
  if (poses.empty()) {
    return Status::FailedPrecondition("undistortion: no propagated poses for the scan at " +
                                      std::to_string(scan_stamp_ns) + " ns");
  }
  for (size_t i = 1; i < poses.size(); ++i) {
    if (poses[i].stamp_ns < poses[i - 1].stamp_ns) {
      return Status::InvalidArgument("undistortion: poses are not sorted by time");
    }
  }
  return Status::Ok();
}

// Moves body-frame points measured at scan_stamp + time to the body frame at
// the last pose. `point(i, &p_in_b, &offset_s)` returns false for a point to
// skip (non-finite); `emit(i, p_in_b_end)` receives the result.
template <class PointFn, class EmitFn>
UndistortionStats UndistortImpl(size_t num_points, int64_t scan_stamp_ns,
                                const std::vector<ImuPose>& poses, PointFn&& point,
                                EmitFn&& emit) {
  UndistortionStats stats;
  const ImuPose& end = poses.back();
  stats.end_stamp_ns = end.stamp_ns;
  const std::vector<double> times_s = RelativeTimes(poses);
  const double scan_start_s = ToSeconds(scan_stamp_ns - poses.front().stamp_ns);
  const double last_s = times_s.back();
  const Eigen::Matrix3d R_e_T = end.R_G_b.transpose();
  for (size_t k = 0; k < num_points; ++k) {
    Eigen::Vector3d p_in_b;
    double offset_s = 0.0;
    if (!point(k, &p_in_b, &offset_s)) {
      ++stats.num_skipped_non_finite;
      continue;
    }
    const double t_s = scan_start_s + offset_s;
    if (t_s < 0.0 || t_s > last_s) ++stats.num_extrapolated;
    const int i = IntervalIndex(times_s, t_s);
    Eigen::Matrix3d R_G_b;
    Eigen::Vector3d p_b_in_G;
    PoseInInterval(poses[i], t_s - times_s[i], &R_G_b, &p_b_in_G);
    emit(k, Eigen::Vector3d(R_e_T * (R_G_b * p_in_b + (p_b_in_G - end.p_b_in_G))));
    ++stats.num_points;
  }
  return stats;
}

}  // namespace

Status UndistortScan(const LidarScan& scan,
                     const std::vector<ImuPose>& poses,
                     const Eigen::Matrix3d& R_imu_lidar,
                     const Eigen::Vector3d& p_lidar_in_imu_m,
                     std::vector<UndistortedPoint>* points,
                     UndistortionStats* stats) {
  SWARMLIO_RETURN_IF_ERROR(CheckPoses(poses, scan.stamp_ns));
  points->clear();
  points->reserve(scan.points.size());
  const UndistortionStats local = UndistortImpl(
      scan.points.size(), scan.stamp_ns, poses,
      [&](size_t k, Eigen::Vector3d* p_in_b, double* offset_s) {
        const LidarPoint& q = scan.points[k];
        if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) ||
            !std::isfinite(q.offset_time_s)) {
          return false;
        }
        *p_in_b = R_imu_lidar * Eigen::Vector3d(q.x, q.y, q.z) + p_lidar_in_imu_m;
        *offset_s = q.offset_time_s;
        return true;
      },
      [&](size_t k, const Eigen::Vector3d& p_in_b_end) {
        const LidarPoint& q = scan.points[k];
        UndistortedPoint out;
        out.p_in_b_end = p_in_b_end;
        out.reflectivity = q.reflectivity;
        out.offset_time_s = q.offset_time_s;
        out.tag = q.tag;
        out.line = q.line;
        points->push_back(out);
      });
  if (stats != nullptr) *stats = local;
  return Status::Ok();
}

Status UndistortPoints(const std::vector<lio::PointXYZT>& points_in_b,
                       int64_t scan_stamp_ns,
                       const std::vector<ImuPose>& poses,
                       std::vector<Eigen::Vector3d>* points_in_b_end,
                       UndistortionStats* stats) {
  SWARMLIO_RETURN_IF_ERROR(CheckPoses(poses, scan_stamp_ns));
  points_in_b_end->clear();
  points_in_b_end->reserve(points_in_b.size());
  const UndistortionStats local = UndistortImpl(
      points_in_b.size(), scan_stamp_ns, poses,
      [&](size_t k, Eigen::Vector3d* p_in_b, double* offset_s) {
        const lio::PointXYZT& q = points_in_b[k];
        if (!q.p_in_b.allFinite() || !std::isfinite(q.time_s)) return false;
        *p_in_b = q.p_in_b;
        *offset_s = q.time_s;
        return true;
      },
      [&](size_t, const Eigen::Vector3d& p_in_b_end) { points_in_b_end->push_back(p_in_b_end); });
  if (stats != nullptr) *stats = local;
  return Status::Ok();
}

}  // namespace swarmlio::lio
