#include "geometry/Shape.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace pyrolume::geometry {

SurfaceShape make_sphere(const glm::dvec3& center, double radius, uint32_t material) {
  SurfaceShape s;
  s.type = SurfaceShape::Type::Sphere;
  s.center = center;
  s.radius = radius;
  s.material = material;
  return s;
}

SurfaceShape make_plane(const glm::dvec3& center, const glm::dvec3& normal, const glm::dvec3& u_hint, double size_u,
                        double size_v, uint32_t material) {
  const double ln = glm::length(normal);
  if (!(ln > 0.0)) throw std::invalid_argument("plane normal is zero");
  SurfaceShape s;
  s.type = SurfaceShape::Type::Plane;
  s.center = center;
  s.normal = normal / ln;
  glm::dvec3 u = u_hint - glm::dot(u_hint, s.normal) * s.normal;
  const double lu = glm::length(u);
  if (!(lu > 1e-12 * glm::length(u_hint))) throw std::invalid_argument("plane u axis is parallel to its normal");
  s.u_axis = u / lu;
  s.half_u = size_u > 0.0 ? 0.5 * size_u : 0.0;
  s.half_v = size_v > 0.0 ? 0.5 * size_v : 0.0;
  s.material = material;
  return s;
}

bool intersect_shape(const SurfaceShape& s, const Ray& ray, double t_max, SurfaceHit& hit) {
  const glm::dvec3& o = ray.origin;
  const glm::dvec3& d = ray.direction;
  double t = 0.0;
  if (s.type == SurfaceShape::Type::Sphere) {
    // Stable quadratic for a non-unit direction (Ray Tracing Gems ch. 7):
    // a t² + 2 b' t + c = 0 with the discriminant from |oc − (b'/a) d|².
    const glm::dvec3 oc = o - s.center;
    const double a = glm::dot(d, d);
    const double b = glm::dot(oc, d);
    const glm::dvec3 perp = oc - (b / a) * d;
    const double disc = a * (s.radius * s.radius - glm::dot(perp, perp));
    if (disc < 0.0) return false;
    const double q = -b - std::copysign(std::sqrt(disc), b);
    double t0 = q / a, t1 = q != 0.0 ? (glm::dot(oc, oc) - s.radius * s.radius) / q : -t0;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > 0.0 && t0 < t_max)
      t = t0;
    else if (t1 > 0.0 && t1 < t_max)
      t = t1;
    else
      return false;
    hit.t = t;
    hit.position = o + t * d;
    const glm::dvec3 local = (hit.position - s.center) / s.radius;
    hit.normal = glm::normalize(local);
    double phi = std::atan2(local.z, local.x);
    if (phi < 0.0) phi += 2.0 * std::numbers::pi;
    const double theta = std::acos(std::clamp(hit.normal.y, -1.0, 1.0));
    hit.uv = glm::dvec2(phi / (2.0 * std::numbers::pi), 1.0 - theta / std::numbers::pi);
  } else {
    const double denom = glm::dot(s.normal, d);
    if (denom == 0.0) return false;
    t = glm::dot(s.center - o, s.normal) / denom;
    if (!(t > 0.0 && t < t_max)) return false;
    const glm::dvec3 p = o + t * d;
    const glm::dvec3 local = p - s.center;
    const glm::dvec3 v_axis = glm::cross(s.normal, s.u_axis);
    const double a = glm::dot(local, s.u_axis), b = glm::dot(local, v_axis);
    if (s.half_u > 0.0 && std::fabs(a) > s.half_u) return false;
    if (s.half_v > 0.0 && std::fabs(b) > s.half_v) return false;
    hit.t = t;
    hit.position = p;
    hit.normal = s.normal;
    hit.uv =
        glm::dvec2(s.half_u > 0.0 ? a / (2.0 * s.half_u) + 0.5 : a, s.half_v > 0.0 ? b / (2.0 * s.half_v) + 0.5 : b);
  }
  hit.kind = HitKind::Shape;
  hit.b1 = hit.b2 = 0.0;
  hit.shading_normal = hit.normal;
  hit.material = s.material;
  return true;
}

}  // namespace pyrolume::geometry
