// Helpers for the evaluation tests: the test data folder, a per-test
// temporary directory and small synthetic trajectories.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "swarmlio/eval/trajectory.h"
#include "swarmlio/math/so3.h"

#include "test_utils/temp_dir.h"

namespace swarmlio::eval::testing {

inline std::string DataFile(const std::string& name) {
  return std::string(SWARMLIO_EVAL_TEST_DATA_DIR) + "/" + name;
}

using swarmlio::testing::TempDir;

inline Eigen::Isometry3d MakePose(const Eigen::Vector3d& rotation_vector,
                                  const Eigen::Vector3d& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(rotation_vector);
  T.translation() = p;
  return T;
}

/// A smooth 3-D curve with turning attitude, stamps t0 + i * dt.
inline Trajectory Curve(int n, double t0_s = 100.0, double dt_s = 0.1) {
  Trajectory trajectory;
  for (int i = 0; i < n; ++i) {
    const double t = i * dt_s;
    trajectory.stamps_s.push_back(t0_s + t);
    trajectory.T_G_b.push_back(
        MakePose(Eigen::Vector3d(0.1 * std::sin(t), 0.05 * t, 0.3 * t),
                 Eigen::Vector3d(3.0 * std::cos(0.4 * t), 2.0 * std::sin(0.4 * t), 0.2 * t)));
  }
  return trajectory;
}

}  // namespace swarmlio::eval::testing
