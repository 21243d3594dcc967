// Synthetic scan points for the teammate tests.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

#include "swarmlio/teammate/scan_types.h"

namespace swarmlio::teammate::testing {

/// `n` points uniformly in a box of half extents `half` around `center`.
inline void AddBlob(const Eigen::Vector3d& center, const Eigen::Vector3d& half, int n,
                    float reflectivity, std::mt19937_64* rng, std::vector<ScanPoint>* points,
                    float time_offset_s = 0.f) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < n; ++k) {
    ScanPoint p;
    p.p_in_b = (center + Eigen::Vector3d(u(*rng) * half.x(), u(*rng) * half.y(), u(*rng) * half.z()))
                   .cast<float>();
    p.reflectivity = reflectivity;
    p.time_offset_s = time_offset_s;
    points->push_back(p);
  }
}

/// A diffuse background: a floor and walls of a 20 x 20 x 4 m room around
/// the origin, `n` points (reflectivity 20-120).
inline void AddBackground(int n, std::mt19937_64* rng, std::vector<ScanPoint>* points) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> face(0, 4);
  for (int k = 0; k < n; ++k) {
    Eigen::Vector3d p(10 * u(*rng), 10 * u(*rng), 2 + 2 * u(*rng));
    switch (face(*rng)) {
      case 0: p.z() = -1.5; break;
      case 1: p.x() = 10; break;
      case 2: p.x() = -10; break;
      case 3: p.y() = 10; break;
      default: p.y() = -10; break;
    }
    ScanPoint s;
    s.p_in_b = p.cast<float>();
    s.reflectivity = static_cast<float>(20 + 50 * (1 + u(*rng)));
    points->push_back(s);
  }
}

}  // namespace swarmlio::teammate::testing
