#include "detector_input.h"

#include <algorithm>

#include "swarmlio/common/time.h"

#include "teammate_state.h"

namespace swarmlio::swarm::internal {
Status DetectorInput::Make(const LidarScan& raw, int64_t t_k, const std::vector<lio::ImuPose>& poses,
                           const SwarmState& x, const teammate::ScanResult& last_detection,
                           int64_t last_detection_ns, double min_reflectivity,
                           std::vector<teammate::ScanPoint>* points) {
  const Eigen::Matrix3d R_imu_lidar = lidar_.QuaternionImuLidar().toRotationMatrix();
  Select(raw, t_k, x, last_detection, last_detection_ns, min_reflectivity, R_imu_lidar);
  SWARMLIO_RETURN_IF_ERROR(
      lio::UndistortScan(selected_, poses, R_imu_lidar, lidar_.p_lidar_in_imu_m, &undistorted_));
  const double end_offset_s = ToSeconds(t_k - raw.stamp_ns);
  points->resize(undistorted_.size());
  for (size_t k = 0; k < undistorted_.size(); ++k) {
    const lio::UndistortedPoint& u = undistorted_[k];
    teammate::ScanPoint& p = (*points)[k];
    p.p_in_b = u.p_in_b_end.cast<float>();
    p.reflectivity = u.reflectivity;
    p.time_offset_s = static_cast<float>(u.offset_time_s - end_offset_s);
  }
  return Status::Ok();
}

void DetectorInput::Select(const LidarScan& raw, int64_t t_k, const SwarmState& x,
                           const teammate::ScanResult& last_detection, int64_t last_detection_ns,
                           double min_reflectivity, const Eigen::Matrix3d& R_imu_lidar) {
  const teammate::TeammateDetectorOptions& d = detector_;
  const float threshold = static_cast<float>(min_reflectivity);
  // Trackers of the last scan, predicted to t_k, in the body frame. The body
  // moves during the scan and the prediction is rough: a generous margin.
  constexpr double kMarginM = 1.0;
  const double radius = std::max(d.association.teammate_region_radius_m,
                                 d.association.temporary_region_radius_m) +
                        swarm_.map_exclusion_radius_m + kMarginM;
  const Eigen::Matrix3d R_b_G = x.ego.R_G_b().transpose();
  std::vector<Eigen::Vector3f> centers_in_lidar;
  for (const teammate::TrackerState& s : last_detection.trackers) {
    const double dt = SecondsBetween(last_detection_ns, t_k);
    const Eigen::Vector3d p_in_b = R_b_G * (s.p_in_Gi + s.v_in_Gi * dt - x.ego.p_b_in_G);
    centers_in_lidar.push_back(
        (R_imu_lidar.transpose() * (p_in_b - lidar_.p_lidar_in_imu_m)).cast<float>());
  }
  const float r2 = static_cast<float>(radius * radius);
  selected_.stamp_ns = raw.stamp_ns;
  selected_.frame_id = raw.frame_id;
  selected_.points.clear();
  for (const LidarPoint& p : raw.points) {
    bool keep = p.reflectivity >= threshold;
    if (!keep) {
      const Eigen::Vector3f q(p.x, p.y, p.z);
      for (const Eigen::Vector3f& c : centers_in_lidar) {
        if ((q - c).squaredNorm() <= r2) {
          keep = true;
          break;
        }
      }
    }
    if (keep) selected_.points.push_back(p);
  }
}

}  // namespace swarmlio::swarm::internal
