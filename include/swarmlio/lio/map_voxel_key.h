// VoxelKey: integer index of an axis-aligned cubic voxel, and its hash.
//
// A point p falls in voxel floor(p / size) on each axis, so voxel k covers the
// half-open interval [k * size, (k + 1) * size) [m]. Used by VoxelFilter and
// LocalMap (both hash voxels with tsl::robin_map).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace swarmlio::lio {

struct VoxelKey {
  int32_t x = 0;
  int32_t y = 0;
  int32_t z = 0;

  friend bool operator==(const VoxelKey& a, const VoxelKey& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
  friend bool operator!=(const VoxelKey& a, const VoxelKey& b) { return !(a == b); }
};

/// 64-bit mix of the three indices (splitmix64 finalizer over a packed key);
/// robin_map uses power-of-two tables, so every output bit must depend on
/// every input bit.
struct VoxelKeyHash {
  size_t operator()(const VoxelKey& k) const {
    uint64_t h = (static_cast<uint64_t>(static_cast<uint32_t>(k.x)) << 42) ^
                 (static_cast<uint64_t>(static_cast<uint32_t>(k.y)) << 21) ^
                 static_cast<uint64_t>(static_cast<uint32_t>(k.z));
    h ^= static_cast<uint64_t>(static_cast<uint32_t>(k.y)) >> 11;  // high bits of y
    h ^= static_cast<uint64_t>(static_cast<uint32_t>(k.x)) * 0x9E3779B97F4A7C15ULL;
    h ^= h >> 30;
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 27;
    h *= 0x94D049BB133111EBULL;
    h ^= h >> 31;
    return static_cast<size_t>(h);
  }
};

/// Index of the voxel of side 1 / inv_size [m] holding coordinate `c` [m].
/// Coordinates beyond the int32 range are clamped (such points are far
/// outside any sensor range and only need a deterministic home).
inline int32_t VoxelIndex(double c, double inv_size) {
  const double f = std::floor(c * inv_size);
  constexpr double kLimit = 2.0e9;
  if (!(f > -kLimit)) return static_cast<int32_t>(-kLimit);  // also catches NaN
  if (f > kLimit) return static_cast<int32_t>(kLimit);
  return static_cast<int32_t>(f);
}

inline VoxelKey VoxelKeyOf(const Eigen::Vector3d& p, double inv_size) {
  return {VoxelIndex(p.x(), inv_size), VoxelIndex(p.y(), inv_size), VoxelIndex(p.z(), inv_size)};
}

/// Centre of voxel `k` of side `size` [m].
inline Eigen::Vector3d VoxelCenter(const VoxelKey& k, double size) {
  return {(k.x + 0.5) * size, (k.y + 0.5) * size, (k.z + 0.5) * size};
}

}  // namespace swarmlio::lio
