#pragma once
// Analytic surfaces: spheres and planes (finite rectangles or unbounded).
#include <cstdint>
#include <glm/glm.hpp>

#include "geometry/Ray.h"

namespace pyrolume::geometry {

struct SurfaceShape {
  enum class Type : uint32_t { Sphere = 0, Plane = 1 };  // = SURFACE_SPHERE / SURFACE_PLANE
  Type type = Type::Sphere;
  glm::dvec3 center{0.0};            // sphere centre; plane: a point on it, the rectangle's centre
  double radius = 1.0;               // sphere
  glm::dvec3 normal{0.0, 1.0, 0.0};  // plane: unit normal
  glm::dvec3 u_axis{1.0, 0.0, 0.0};  // plane: unit, perpendicular to normal; v axis = cross(normal, u_axis)
  // Plane half extents along u and v; <= 0: unbounded along that axis (both
  // <= 0: an infinite plane).
  double half_u = 0.0, half_v = 0.0;
  uint32_t material = 0;
};

SurfaceShape make_sphere(const glm::dvec3& center, double radius, uint32_t material);
// A rectangle of size_u × size_v centred at `center` (0 for an unbounded
// direction). `u_hint` picks the u axis: it is projected into the plane
// (any vector not parallel to `normal`). Throws std::invalid_argument on a zero
// normal or a u_hint parallel to it.
SurfaceShape make_plane(const glm::dvec3& center, const glm::dvec3& normal, const glm::dvec3& u_hint, double size_u,
                        double size_v, uint32_t material);

// Closest hit with 0 < t < t_max. Spheres: either root (a ray from inside hits
// the inner side). Sets t, position, normal (= shading normal), uv, material,
// kind = Shape; `primitive` is left to the caller.
//   sphere uv: u = atan2(z, x)/(2π) wrapped to [0, 1) in the sphere's frame,
//              v = 1 − θ/π with θ from +y (v = 1 at the north pole).
//   plane uv:  finite axis: a/(2·half) + 0.5 ∈ [0, 1] (a = distance from the
//              centre along the axis); unbounded axis: a (one repeat per unit).
bool intersect_shape(const SurfaceShape& shape, const Ray& ray, double t_max, SurfaceHit& hit);

}  // namespace pyrolume::geometry
