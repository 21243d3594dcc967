#include "swarmlio/sim/lidar_model.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"
#include "swarmlio/math/angles.h"
#include "swarmlio/sim/random.h"
#include "swarmlio/sim/reflectivity.h"

namespace swarmlio::sim {
namespace {

// Sub-streams of a LidarModel's seed for the imperfections (the base stream is
// the seed itself, as it always was).
constexpr uint64_t kImperfectionStream = 1;
constexpr uint64_t kSecondReturnStream = 2;
// Sparse-lattice surfaces (Material::return_probability < 1): one
// counter-based draw per surface crossing, CounterUniform(lattice key, pulse,
// ray * kMaxLatticeCrossings + crossing).
constexpr uint64_t kLatticeStream = 3;
constexpr uint64_t kMaxLatticeCrossings = 16;  // per ray; the last crossing returns
enum CastRay : uint64_t { kMainRay = 0, kProbeRay = 1 };
// A ray passing through a lattice surface continues this far past it [m].
constexpr double kLatticeStepM = 1e-6;
// Counter-based draws of one pulse (CounterUniform(key, pulse, draw)).
enum PulseDraw : uint64_t {
  kAngularNoise = 0,  // and 1: a Box-Muller pair
  kRangeDropout = 2,
  kMixDecision = 3,
  kMixWeight = 4,
  kProbeRadius = 5,
  kProbeAngle = 6,
  kSecondReturnNoise = 7,  // and 8
};

// Two independent N(0, 1) numbers from draws `first` and `first + 1` (Box-Muller).
void NormalPair(uint64_t key, uint64_t pulse, uint64_t first, double* a, double* b) {
  const double radius = std::sqrt(-2.0 * std::log(CounterUniform(key, pulse, first)));
  const double angle = 2.0 * M_PI * CounterUniform(key, pulse, first + 1);
  *a = radius * std::cos(angle);
  *b = radius * std::sin(angle);
}
// The incidence term of the range noise stops growing at 85 deg.
const double kMinCosIncidence = std::cos(85.0 * kRadiansPerDegree);
constexpr uint8_t kFirstReturn = 0x10;   // Livox tag bits 5:4 = 01
constexpr uint8_t kSecondReturn = 0x20;  // Livox tag bits 5:4 = 10

// Unit vectors normal to the beam `d` (LiDAR frame): h in the x-y plane, v =
// d x h (towards +z for a horizontal beam).
void FootprintAxes(const Eigen::Vector3d& d, Eigen::Vector3d* h, Eigen::Vector3d* v) {
  Eigen::Vector3d a = Eigen::Vector3d::UnitZ().cross(d);
  if (a.squaredNorm() < 1e-12) a = Eigen::Vector3d::UnitY();  // a beam along z
  *h = a.normalized();
  *v = d.cross(*h);
}

// Measured range of a return from true range `r` (see LidarImperfectionOptions).
double MeasuredRange(const LidarOptions& sensor,
                     const LidarImperfectionOptions& imp,
                     double divergence_rms_rad,
                     double r,
                     double cos_incidence,
                     double reflectivity,
                     double unit_normal_draw) {
  double sigma = sensor.range_noise_stddev_m;
  if (imp.range_noise_per_m > 0.0 || imp.incidence_noise) {
    double variance = sigma * sigma + std::pow(imp.range_noise_per_m * r, 2);
    if (imp.incidence_noise) {
      const double c = std::clamp(cos_incidence, kMinCosIncidence, 1.0);
      const double spread = r * divergence_rms_rad * std::sqrt(1.0 - c * c) / c / 4.0;
      variance += spread * spread;
    }
    sigma = std::sqrt(variance);
  }
  double range = r;
  if (imp.low_reflectivity_bias_m != 0.0) {
    range += imp.low_reflectivity_bias_m *
             std::max(0.0, 1.0 - reflectivity / imp.low_reflectivity_threshold);
  }
  return range + sigma * unit_normal_draw;
}

// Conservative test whether the ray passes within `radius` of `center` before `t_max`.
bool RayNearSphere(const Ray& ray, const Eigen::Vector3d& center, double radius, double t_max) {
  const Eigen::Vector3d w = center - ray.origin;
  const double tc = w.dot(ray.direction);
  if (tc < -radius || tc - radius > t_max) return false;
  return w.squaredNorm() - tc * tc <= radius * radius;
}

}  // namespace

LidarModel::LidarModel(const SimulatedLidarOptions& options,
                       const Trajectory* own_trajectory,
                       const Scene* scene,
                       const std::vector<MovingObject>* objects,
                       int own_object,
                       uint64_t seed)
    : options_(options),
      pattern_(options.sensor),
      own_trajectory_(own_trajectory),
      scene_(scene),
      objects_(objects),
      own_object_(own_object),
      t0_(options.start_time_s),
      period_(1.0 / options.sensor.scan_rate_hz),
      R_imu_lidar_(options.sensor.QuaternionImuLidar().toRotationMatrix()),
      rng_(seed),
      imperfection_key_(DeriveSeed(seed, 0, kImperfectionStream)),
      second_return_rng_(DeriveSeed(seed, 0, kSecondReturnStream)),
      lattice_key_(DeriveSeed(seed, 0, kLatticeStream)) {
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

void LidarModel::CollectCandidates(double start_time_s) {
  candidates_.clear();
  if (objects_ == nullptr) return;
  constexpr int kSamples = 16;
  for (int j = 0; j < static_cast<int>(objects_->size()); ++j) {
    if (j == own_object_) continue;
    const MovingObject& obj = (*objects_)[j];
    const Eigen::Vector3d center = obj.trajectory->PositionAt(start_time_s + 0.5 * period_);
    double deviation = 0.0;
    double step = 0.0;
    Eigen::Vector3d previous = obj.trajectory->PositionAt(start_time_s);
    for (int s = 0; s <= kSamples; ++s) {
      const Eigen::Vector3d p = obj.trajectory->PositionAt(start_time_s + period_ * s / kSamples);
      deviation = std::max(deviation, (p - center).norm());
      step = std::max(step, (p - previous).norm());
      previous = p;
    }
    candidates_.push_back({j, center, obj.bounding_radius_m + deviation + step + 0.05});
  }
}

LidarModel::Footprint LidarModel::BeamFootprint() const {
  const LidarImperfectionOptions& imp = options_.imperfections;
  Footprint f;
  f.angular_sigma = imp.angular_noise_deg * kRadiansPerDegree;
  f.half_divergence_h = 0.5 * imp.beam_divergence_horizontal_deg * kRadiansPerDegree;
  f.half_divergence_v = 0.5 * imp.beam_divergence_vertical_deg * kRadiansPerDegree;
  f.divergence_rms = std::sqrt(2.0 * (f.half_divergence_h * f.half_divergence_h +
                                      f.half_divergence_v * f.half_divergence_v));
  f.needs_axes = f.angular_sigma > 0.0 || imp.SamplesFootprint();
  return f;
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
  CollectCandidates(scan->start_time_s);

  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal;
  const Footprint footprint = BeamFootprint();
  const int64_t first_pulse = frame * pulses_per_frame;
  for (int64_t i = 0; i < pulses_per_frame; ++i) {
    SimulatePulse(first_pulse + i, footprint, &uniform, &normal, &scan->points);
  }
}

LidarModel::Pulse LidarModel::AimPulse(int64_t k, const Footprint& footprint) const {
  Pulse pulse;
  pulse.t = t0_ + static_cast<double>(k) / pattern_.pulse_rate_hz();
  pattern_.Direction(k, &pulse.dir_l, &pulse.line);
  pulse.T_W_l = LidarPoseAt(pulse.t);

  // Imperfections: counter-based draws (a pure function of the pulse), so
  // each effect sees the same numbers whatever else is enabled.
  pulse.index = static_cast<uint64_t>(k);
  pulse.beam_l = pulse.dir_l;  // where the pulse really goes
  if (footprint.needs_axes) FootprintAxes(pulse.dir_l, &pulse.axis_h, &pulse.axis_v);
  if (footprint.angular_sigma > 0.0) {
    double n_h, n_v;
    NormalPair(imperfection_key_, pulse.index, kAngularNoise, &n_h, &n_v);
    pulse.beam_l =
        (pulse.dir_l + footprint.angular_sigma * (n_h * pulse.axis_h + n_v * pulse.axis_v))
            .normalized();
  }
  pulse.ray = Ray{pulse.T_W_l.p_b_in_W, pulse.T_W_l.R_W_b * pulse.beam_l};
  return pulse;
}

void LidarModel::SimulatePulse(int64_t k,
                               const Footprint& footprint,
                               std::uniform_real_distribution<double>* uniform,
                               std::normal_distribution<double>* normal,
                               std::vector<SimulatedPoint>* points) {
  const LidarOptions& sensor = options_.sensor;
  const LidarImperfectionOptions& imp = options_.imperfections;
  const Pulse pulse = AimPulse(k, footprint);
  const Hit main = Cast(pulse.ray, pulse.t, pulse.index, kMainRay);
  // Draw the random numbers for every pulse so that the stream does not
  // depend on the geometry hit.
  const double dropout_draw = (*uniform)(rng_);
  const double range_draw = (*normal)(rng_);
  if (!main.hit.hit() || main.hit.t < sensor.blind_range_m) return;
  if (dropout_draw < options_.dropout_probability) return;
  if (imp.range_dropout_at_max_range > 0.0) {
    const double loss =
        imp.range_dropout_at_max_range *
        std::pow(std::min(1.0, main.hit.t / sensor.max_range_m), imp.range_dropout_exponent);
    if (CounterUniform(imperfection_key_, pulse.index, kRangeDropout) <= loss) return;
  }
  SimulatedPoint p;
  p.t_s = pulse.t;
  p.true_range_m = main.hit.t;
  p.true_p_in_lidar = pulse.beam_l * main.hit.t;
  p.cos_incidence = std::abs(main.hit.normal.dot(pulse.ray.direction));
  p.reflectivity =
      Reflectivity(options_.reflectivity, *main.material, main.hit.t, p.cos_incidence, &rng_);
  p.line = pulse.line;
  p.object = main.object;
  p.primitive = main.hit.primitive;

  // Depth edges: a second sample of the footprint.
  double signal_range = main.hit.t;
  bool two_returns = false;
  Hit other;
  Eigen::Vector3d probe_l = pulse.beam_l;
  if (ProbeEdge(pulse, footprint, main, &other, &probe_l)) {
    if (imp.multi_return) {
      two_returns = true;
    } else {
      const double weight = 1.0 - CounterUniform(imperfection_key_, pulse.index, kMixWeight);
      signal_range = main.hit.t + weight * (other.hit.t - main.hit.t);
      p.mixed = true;
      p.mixed_other_range_m = other.hit.t;
    }
  }
  p.p_in_lidar = pulse.dir_l * MeasuredRange(sensor, imp, footprint.divergence_rms, signal_range,
                                             p.cos_incidence, p.reflectivity, range_draw);
  if (!two_returns) {
    points->push_back(p);
    return;
  }
  AppendDualReturn(pulse, footprint, main, other, probe_l, p, points);
}

bool LidarModel::ProbeEdge(const Pulse& pulse,
                           const Footprint& footprint,
                           const Hit& main,
                           Hit* other,
                           Eigen::Vector3d* probe_l) const {
  const LidarImperfectionOptions& imp = options_.imperfections;
  const bool sampled =
      imp.multi_return ||
      (imp.mixed_pixel_probability > 0.0 &&
       CounterUniform(imperfection_key_, pulse.index, kMixDecision) <= imp.mixed_pixel_probability);
  if (!sampled) return false;
  // Uniform over the elliptic footprint.
  const double radius = std::sqrt(CounterUniform(imperfection_key_, pulse.index, kProbeRadius));
  const double angle = 2.0 * M_PI * CounterUniform(imperfection_key_, pulse.index, kProbeAngle);
  *probe_l =
      (pulse.beam_l + radius * (std::cos(angle) * footprint.half_divergence_h * pulse.axis_h +
                                std::sin(angle) * footprint.half_divergence_v * pulse.axis_v))
          .normalized();
  *other =
      Cast(Ray{pulse.ray.origin, pulse.T_W_l.R_W_b * *probe_l}, pulse.t, pulse.index, kProbeRay);
  const bool other_surface =
      other->object != main.object || other->hit.primitive != main.hit.primitive;
  return other->hit.hit() && other->hit.t >= options_.sensor.blind_range_m && other_surface &&
         std::abs(other->hit.t - main.hit.t) > imp.edge_min_separation_m;
}

void LidarModel::AppendDualReturn(const Pulse& pulse,
                                  const Footprint& footprint,
                                  const Hit& main,
                                  const Hit& other,
                                  const Eigen::Vector3d& probe_l,
                                  SimulatedPoint p,
                                  std::vector<SimulatedPoint>* points) {
  // Dual return: both surfaces, reported along the same nominal direction,
  // the nearer one first.
  SimulatedPoint q = p;
  q.true_range_m = other.hit.t;
  q.true_p_in_lidar = probe_l * other.hit.t;
  q.cos_incidence = std::abs(other.hit.normal.dot(pulse.T_W_l.R_W_b * probe_l));
  q.reflectivity = Reflectivity(options_.reflectivity, *other.material, other.hit.t,
                                q.cos_incidence, &second_return_rng_);
  q.object = other.object;
  q.primitive = other.hit.primitive;
  double second_noise, unused;
  NormalPair(imperfection_key_, pulse.index, kSecondReturnNoise, &second_noise, &unused);
  q.p_in_lidar =
      pulse.dir_l * MeasuredRange(options_.sensor, options_.imperfections, footprint.divergence_rms,
                                  other.hit.t, q.cos_incidence, q.reflectivity, second_noise);
  const bool main_first = main.hit.t <= other.hit.t;
  p.tag = main_first ? kFirstReturn : kSecondReturn;
  q.tag = main_first ? kSecondReturn : kFirstReturn;
  points->push_back(main_first ? p : q);
  points->push_back(main_first ? q : p);
}

LidarModel::Hit LidarModel::Cast(const Ray& ray, double t, uint64_t pulse, uint64_t ray_id) const {
  double t_min = 0.0;
  for (uint64_t crossing = 0;; ++crossing) {
    const Hit h = CastFrom(ray, t, t_min);
    if (!h.hit.hit() || h.material->return_probability >= 1.0 ||
        crossing + 1 >= kMaxLatticeCrossings) {
      return h;
    }
    const uint64_t draw = ray_id * kMaxLatticeCrossings + crossing;
    if (CounterUniform(lattice_key_, pulse, draw) <= h.material->return_probability) return h;
    t_min = h.hit.t + kLatticeStepM;  // through the lattice
  }
}

LidarModel::Hit LidarModel::CastFrom(const Ray& ray, double t, double t_min) const {
  const double max_range = options_.sensor.max_range_m;
  Hit h;
  if (scene_->Intersect(ray, t_min, max_range, &h.hit)) {
    h.material = &scene_->primitives()[h.hit.primitive].material();
  }
  for (const Candidate& c : candidates_) {
    if (!RayNearSphere(ray, c.center, c.radius, h.hit.hit() ? h.hit.t : max_range)) continue;
    const MovingObject& obj = (*objects_)[c.object];
    const Pose T_W_o = obj.trajectory->PoseAt(t);
    // The ray in the object's body frame.
    const Ray ray_o{T_W_o.R_W_b.transpose() * (ray.origin - T_W_o.p_b_in_W),
                    T_W_o.R_W_b.transpose() * ray.direction};
    RayHit hit_o;
    if (IntersectBruteForce(obj.parts_b, ray_o, t_min, h.hit.hit() ? h.hit.t : max_range, &hit_o)) {
      h.hit = hit_o;
      h.hit.normal = T_W_o.R_W_b * hit_o.normal;
      h.object = c.object;
      h.material = &obj.parts_b[hit_o.primitive].material();
    }
  }
  return h;
}

}  // namespace swarmlio::sim
