#include "swarmlio/sim/lidar_model.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"
#include "swarmlio/sim/reflectivity.h"

namespace swarmlio::sim {
namespace {

// Conservative test whether the ray passes within `radius` of `center` before `t_max`.
bool RayNearSphere(const Ray& ray, const Eigen::Vector3d& center, double radius, double t_max) {
  const Eigen::Vector3d w = center - ray.origin;
  const double tc = w.dot(ray.direction);
  if (tc < -radius || tc - radius > t_max) return false;
  return w.squaredNorm() - tc * tc <= radius * radius;
}

}  // namespace

LidarModel::LidarModel(const SimulatedLidarOptions& options, const Trajectory* own_trajectory,
                       const Scene* scene, const std::vector<MovingObject>* objects,
                       int own_object, uint64_t seed)
    : options_(options),
      pattern_(options.sensor),
      own_trajectory_(own_trajectory),
      scene_(scene),
      objects_(objects),
      own_object_(own_object),
      t0_(options.start_time_s),
      period_(1.0 / options.sensor.scan_rate_hz),
      R_imu_lidar_(options.sensor.QuaternionImuLidar().toRotationMatrix()),
      rng_(seed) {
  CHECK(options_.Validate().empty()) << options_.Validate();
  CHECK(own_trajectory_ != nullptr && scene_ != nullptr);
  CHECK(scene_->built());
}

Pose LidarModel::LidarPoseAt(double t) const {
  const Pose T_W_b = own_trajectory_->PoseAt(t);
  Pose T_W_l;
  T_W_l.R_W_b = T_W_b.R_W_b * R_imu_lidar_;
  T_W_l.p_b_in_W = T_W_b.p_b_in_W + T_W_b.R_W_b * options_.sensor.p_lidar_in_imu_m;
  return T_W_l;
}

void LidarModel::Scan(int64_t frame, SimulatedScan* scan) {
  scan->frame_index = frame;
  scan->start_time_s = FrameStart(frame);
  scan->period_s = period_;
  const int64_t pulses_per_frame = pattern_.pulses_per_frame();
  scan->num_pulses = pulses_per_frame;
  scan->points.clear();
  scan->points.reserve(static_cast<size_t>(pulses_per_frame));

  // Bounding spheres of the other moving objects over this frame.
  candidates_.clear();
  if (objects_ != nullptr) {
    constexpr int kSamples = 16;
    for (int j = 0; j < static_cast<int>(objects_->size()); ++j) {
      if (j == own_object_) continue;
      const MovingObject& obj = (*objects_)[j];
      const Eigen::Vector3d center = obj.trajectory->PositionAt(scan->start_time_s + 0.5 * period_);
      double deviation = 0.0;
      double step = 0.0;
      Eigen::Vector3d previous = obj.trajectory->PositionAt(scan->start_time_s);
      for (int s = 0; s <= kSamples; ++s) {
        const Eigen::Vector3d p =
            obj.trajectory->PositionAt(scan->start_time_s + period_ * s / kSamples);
        deviation = std::max(deviation, (p - center).norm());
        step = std::max(step, (p - previous).norm());
        previous = p;
      }
      candidates_.push_back({j, center, obj.bounding_radius_m + deviation + step + 0.05});
    }
  }

  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal;
  const LidarOptions& sensor = options_.sensor;
  const int64_t first_pulse = frame * pulses_per_frame;
  const double max_range = sensor.max_range_m;
  for (int64_t i = 0; i < pulses_per_frame; ++i) {
    const int64_t k = first_pulse + i;
    const double t = t0_ + static_cast<double>(k) / pattern_.pulse_rate_hz();
    Eigen::Vector3d dir_l;
    uint8_t line;
    pattern_.Direction(k, &dir_l, &line);
    const Pose T_W_l = LidarPoseAt(t);
    const Ray ray{T_W_l.p_b_in_W, T_W_l.R_W_b * dir_l};

    RayHit best;
    int best_object = -1;
    const Material* material = nullptr;
    if (scene_->Intersect(ray, 0.0, max_range, &best)) {
      material = &scene_->primitives()[best.primitive].material();
    }
    for (const Candidate& c : candidates_) {
      if (!RayNearSphere(ray, c.center, c.radius, best.hit() ? best.t : max_range)) continue;
      const MovingObject& obj = (*objects_)[c.object];
      const Pose T_W_o = obj.trajectory->PoseAt(t);
      // The ray in the object's body frame.
      const Ray ray_o{T_W_o.R_W_b.transpose() * (ray.origin - T_W_o.p_b_in_W),
                      T_W_o.R_W_b.transpose() * ray.direction};
      RayHit hit_o;
      if (IntersectBruteForce(obj.parts_b, ray_o, 0.0, best.hit() ? best.t : max_range,
                              &hit_o)) {
        best = hit_o;
        best.normal = T_W_o.R_W_b * hit_o.normal;
        best_object = c.object;
        material = &obj.parts_b[hit_o.primitive].material();
      }
    }
    // Draw the random numbers for every pulse so that the stream does not
    // depend on the geometry hit.
    const double dropout_draw = uniform(rng_);
    const double range_draw = normal(rng_);
    if (!best.hit() || best.t < sensor.blind_range_m) continue;
    if (dropout_draw < options_.dropout_probability) continue;
    SimulatedPoint p;
    p.t_s = t;
    p.true_range_m = best.t;
    const double range = best.t + sensor.range_noise_stddev_m * range_draw;
    p.p_in_lidar = dir_l * range;
    p.reflectivity = Reflectivity(options_.reflectivity, *material, best.t,
                                  std::abs(best.normal.dot(ray.direction)), &rng_);
    p.line = line;
    p.object = best_object;
    p.primitive = best.primitive;
    scan->points.push_back(p);
  }
}

}  // namespace swarmlio::sim
