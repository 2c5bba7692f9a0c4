// Small numeric helpers shared across host/ (one definition each: the core
// library is compiled in unity batches, so two file-local copies of one name
// would collide).
#pragma once

#include <algorithm>
#include <numbers>

#include <glm/vec3.hpp>

namespace pyrolume {

inline constexpr double kPi = std::numbers::pi;

// The largest component: a colour's or a coefficient's bound.
inline double max3(const glm::dvec3& v) { return std::max({v.x, v.y, v.z}); }

}  // namespace pyrolume
