// Seeded randomness of the simulator. Every random stream (a drone's IMU
// noise, its LiDAR noise, its imperfections, its calibration error, ...) is a
// std::mt19937_64 seeded with DeriveSeed(scenario seed, drone, stream), so a
// stream never depends on another stream, on thread scheduling or on which
// effects are enabled elsewhere.
#pragma once

#include <cstdint>

namespace swarmlio::sim {

/// Independent 64-bit seed for (base seed, drone, stream) via SplitMix64.
uint64_t DeriveSeed(uint64_t seed, uint64_t drone, uint64_t stream);

/// Counter-based draw: the `draw`-th uniform number in (0, 1] of item `item`
/// (e.g. a LiDAR pulse) of stream `key`. A pure function of its arguments, so
/// one effect's draws never depend on which other effects draw.
double CounterUniform(uint64_t key, uint64_t item, uint64_t draw);

/// Stream ids of DeriveSeed(seed, drone, stream); one place so that two uses
/// can never share a stream by accident.
namespace streams {
constexpr uint64_t kImu = 1;               // ImuModel (sub-streams derived inside)
constexpr uint64_t kLidar = 2;             // LidarModel (sub-streams derived inside)
constexpr uint64_t kTrajectory = 3;        // flight plans (excite targets)
constexpr uint64_t kCalibrationError = 4;  // calibration handed to the estimator
constexpr uint64_t kClockDrift = 5;        // per-drone clock drift
}  // namespace streams

}  // namespace swarmlio::sim
