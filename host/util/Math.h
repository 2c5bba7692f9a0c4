// Small numeric helpers shared across host/ (one definition each: the core
// library is compiled in unity batches, so two file-local copies of one name
// would collide).
#pragma once

#include <algorithm>
#include <cstdint>
#include <numbers>

#include <glm/vec3.hpp>

namespace pyrolume {

inline constexpr double kPi = std::numbers::pi;

// The largest component: a colour's or a coefficient's bound.
inline double max3(const glm::dvec3& v) { return std::max({v.x, v.y, v.z}); }

// a + b, held at UINT64_MAX instead of wrapping (voxel counts of huge tiles).
inline uint64_t saturating_add(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }

// A row-major 3×3 matrix (a colour-space table as published) times v.
inline glm::dvec3 mul(const double (&m)[3][3], const glm::dvec3& v) {
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

}  // namespace pyrolume
