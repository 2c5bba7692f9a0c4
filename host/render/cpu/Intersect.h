#pragma once
// Ray vs medium bounds (sphere, axis-aligned box) for the CPU reference. They
// return the parametric interval [t0, t1] where the (infinite) line is inside the
// bounds; callers clip to t >= 0. Tangent and grazing rays give an empty or
// zero-length interval, never NaN.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace pyrolume::cpu {

struct RayInterval {
  bool hit = false;
  double t0 = 0.0, t1 = 0.0;
};

// Unit-length dir. The discriminant is computed as r² − |Δ − (Δ·d) d|² (the
// perpendicular distance form, Haines et al., Ray Tracing Gems ch. 7), which does
// not cancel catastrophically for distant spheres the way b² − c does.
inline RayInterval intersect_sphere(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& center,
                                    double radius) {
  glm::dvec3 delta = o - center;
  double b = glm::dot(delta, d);
  glm::dvec3 perp = delta - b * d;
  double disc = radius * radius - glm::dot(perp, perp);
  if (!(disc >= 0.0)) return {};
  double s = std::sqrt(disc);
  return {true, -b - s, -b + s};
}

// Slab test (Kay & Kajiya 1986). An axis with d == 0 exactly is handled on its own
// so that 0 · inf never produces NaN (ray parallel to and lying on a face plane).
inline RayInterval intersect_box(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& lo,
                                 const glm::dvec3& hi) {
  double t0 = -std::numeric_limits<double>::infinity();
  double t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return {};
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 <= t1)) return {};
  return {true, t0, t1};
}

inline RayInterval intersect_bounds(const glm::dvec3& o, const glm::dvec3& d, const Bounds& bounds) {
  if (bounds.kind == Bounds::Kind::Sphere) return intersect_sphere(o, d, bounds.center, bounds.radius);
  return intersect_box(o, d, bounds.min, bounds.max);
}

}  // namespace pyrolume::cpu
