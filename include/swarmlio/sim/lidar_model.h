// LiDAR measurement model: casts each pulse from the sensor pose at the
// pulse's own time against the static scene and against every other moving
// object (teammates, decoys) at that same time. Imperfections (beam angular
// noise, range noise growing with range and incidence, range walk on dark
// surfaces, mixed pixels and multiple returns at depth edges, range-dependent
// dropouts) are in LidarImperfectionOptions (lidar_options.h), off by default.
// A surface whose Material::return_probability is below 1 is a sparse lattice
// (the reflective_shell airframe, drone_body.h): a ray crossing it returns from
// it with that probability, else passes through to what lies behind, drawn per
// pulse and crossing from the LiDAR's seed (deterministic, thread-independent).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "swarmlio/sim/drone_body.h"
#include "swarmlio/sim/lidar_options.h"
#include "swarmlio/sim/lidar_pattern.h"
#include "swarmlio/sim/scene.h"
#include "swarmlio/sim/trajectory.h"

namespace swarmlio::sim {

/// One return, with ground truth.
struct SimulatedPoint {
  double t_s = 0.0;                                       // true time of the pulse [s]
  Eigen::Vector3d p_in_lidar = Eigen::Vector3d::Zero();   // measured (with all noise) [m]
  double true_range_m = 0.0;  // range of the surface hit along the beam [m]
  /// Where the beam (with its angular error) hit that surface, LiDAR frame [m].
  Eigen::Vector3d true_p_in_lidar = Eigen::Vector3d::Zero();
  double cos_incidence = 1.0;                             // |cos| beam vs surface normal
  double reflectivity = 0.0;                              // Livox 0-255 scale
  uint8_t line = 0;
  uint8_t tag = 0x10;                // Livox tag: bits 5:4 return number (01 first, 10 second)
  bool mixed = false;                // a mixed pixel (range between two surfaces of the footprint)
  double mixed_other_range_m = 0.0;  // mixed pixels: range of the other surface [m]
  int object = -1;      // -1: static scene; else the index of the moving object hit
  int primitive = -1;   // index into the scene's or the object's primitives
};

struct SimulatedScan {
  int64_t frame_index = 0;
  double start_time_s = 0.0;  // true time of the first pulse
  double period_s = 0.0;      // 1 / frame rate
  int64_t num_pulses = 0;     // pulses fired (returns + misses + dropouts)
  std::vector<SimulatedPoint> points;  // in firing (time) order
};

class LidarModel {
 public:
  /// All pointers must outlive the model. `own_object` is the index of the
  /// carrying drone in `objects` (never seen by its own sensor), or -1. The
  /// first pulse of frame 0 fires at true time options.start_time_s.
  LidarModel(const SimulatedLidarOptions& options, const Trajectory* own_trajectory,
             const Scene* scene, const std::vector<MovingObject>* objects, int own_object,
             uint64_t seed);

  double FrameStart(int64_t frame) const { return t0_ + static_cast<double>(frame) * period_; }
  double period() const { return period_; }
  int64_t pulses_per_frame() const { return pattern_.pulses_per_frame(); }
  /// R_imu_lidar of the options projected onto SO(3) (the rotation used).
  const Eigen::Matrix3d& R_imu_lidar() const { return R_imu_lidar_; }

  /// Pose of the LiDAR frame in W at time t: R_W_l, p_l_in_W.
  Pose LidarPoseAt(double t) const;

  /// Simulates frame `frame` into *scan (frames are independent of each other
  /// except for the random stream: call them in order for reproducible noise).
  void Scan(int64_t frame, SimulatedScan* scan);

 private:
  struct Candidate {
    int object;
    Eigen::Vector3d center;
    double radius;
  };
  // The closest surface along a ray at time t (static scene and other objects).
  struct Hit {
    RayHit hit;  // normal in W
    int object = -1;
    const Material* material = nullptr;
  };
  // The surface ray `ray_id` (kMainRay, kProbeRay) of pulse `pulse` returns
  // from: the closest one, or past sparse-lattice surfaces it passes through
  // (Material::return_probability, counter-based draws of lattice_key_).
  Hit Cast(const Ray& ray, double t, uint64_t pulse, uint64_t ray_id) const;
  // The closest surface with ray parameter >= t_min.
  Hit CastFrom(const Ray& ray, double t, double t_min) const;

  // The beam shape of the imperfections, the same for every pulse [rad].
  struct Footprint {
    double angular_sigma = 0.0;      // pointing noise
    double half_divergence_h = 0.0;  // half-angles of the elliptic footprint
    double half_divergence_v = 0.0;
    double divergence_rms = 0.0;  // of the footprint (incidence noise)
    bool needs_axes = false;      // angular noise or footprint sampling
  };
  // One pulse: its time, nominal direction and the beam it really fires.
  struct Pulse {
    uint64_t index = 0;     // the pulse counter (imperfection draws)
    double t = 0.0;         // true time [s]
    Eigen::Vector3d dir_l;  // nominal direction (LiDAR frame), the reported one
    uint8_t line = 0;
    Pose T_W_l;                                        // LiDAR pose at t
    Eigen::Vector3d beam_l;                            // where the pulse really goes (LiDAR frame)
    Eigen::Vector3d axis_h = Eigen::Vector3d::Zero();  // footprint axes (FootprintAxes)
    Eigen::Vector3d axis_v = Eigen::Vector3d::Zero();
    Ray ray;  // the beam in W
  };
  Footprint BeamFootprint() const;
  // Bounding spheres of the other moving objects over the frame starting at
  // `start_time_s` (candidates_).
  void CollectCandidates(double start_time_s);
  Pulse AimPulse(int64_t k, const Footprint& footprint) const;
  // Simulates pulse k: appends its return(s) to *points, if any.
  void SimulatePulse(int64_t k,
                     const Footprint& footprint,
                     std::uniform_real_distribution<double>* uniform,
                     std::normal_distribution<double>* normal,
                     std::vector<SimulatedPoint>* points);
  // Depth edges: true when a second sample of the footprint (*probe_l) hits
  // another surface (*other) at a depth step from `main`.
  bool ProbeEdge(const Pulse& pulse,
                 const Footprint& footprint,
                 const Hit& main,
                 Hit* other,
                 Eigen::Vector3d* probe_l) const;
  // Dual return: `p` (of `main`) and the return of `other` at probe_l, the
  // nearer one first.
  void AppendDualReturn(const Pulse& pulse,
                        const Footprint& footprint,
                        const Hit& main,
                        const Hit& other,
                        const Eigen::Vector3d& probe_l,
                        SimulatedPoint p,
                        std::vector<SimulatedPoint>* points);

  SimulatedLidarOptions options_;
  LidarPattern pattern_;
  const Trajectory* own_trajectory_;
  const Scene* scene_;
  const std::vector<MovingObject>* objects_;
  int own_object_;
  double t0_;
  double period_;
  Eigen::Matrix3d R_imu_lidar_;
  std::mt19937_64 rng_;                // range noise, random dropouts, reflectivity
  uint64_t imperfection_key_;          // LidarImperfectionOptions: CounterUniform(key, pulse, draw)
  std::mt19937_64 second_return_rng_;  // reflectivity of second returns
  uint64_t lattice_key_;               // sparse-lattice surfaces: CounterUniform(key, pulse, draw)
  std::vector<Candidate> candidates_;
};

}  // namespace swarmlio::sim
