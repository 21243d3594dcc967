// Test helper: seeded random draws (normal and uniform scalars, Gaussian
// vectors, unit axes, rotations), deterministic for a seed. Tests derive
// their own samplers of states and measurements from it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>

#include "swarmlio/math/so3.h"

namespace swarmlio::testing {

class RandomSampler {
 public:
  explicit RandomSampler(unsigned seed) : rng_(seed) {}
  double Normal() { return normal_(rng_); }
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng_); }
  Eigen::Vector3d Gaussian3(double scale) {
    return scale * Eigen::Vector3d(Normal(), Normal(), Normal());
  }
  Eigen::VectorXd Gaussian(int n, double scale) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v[i] = scale * Normal();
    return v;
  }
  Eigen::Vector3d Axis() { return Gaussian3(1.0).normalized(); }
  // Rotation by `angle` about a random axis (uniformly random when < 0).
  Eigen::Quaterniond Rotation(double angle) {
    if (angle < 0) {
      return Eigen::Quaterniond(
          Eigen::Vector4d(Normal(), Normal(), Normal(), Normal()).normalized());
    }
    return so3::ExpQuaternion(Axis() * angle);
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> normal_;
};

}  // namespace swarmlio::testing
