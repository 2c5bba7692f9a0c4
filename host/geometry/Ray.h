#pragma once
// Rays and surface hits of the CPU reference (double precision).
#include <cstdint>
#include <glm/glm.hpp>

namespace pyrolume::geometry {

// Points o + t·d for t in (0, t_max). d need not be unit length: t is in units
// of |d|.
struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, 1.0};
};

enum class HitKind : uint32_t { Triangle = 0, Shape = 1 };

struct SurfaceHit {
  double t = 0.0;
  HitKind kind = HitKind::Triangle;
  uint32_t primitive = 0;  // Triangle: index in Bvh::triangles (BVH order); Shape: index in the shape list
  // Barycentrics of vertices 1 and 2 (vertex 0 has 1 − b1 − b2). Shapes: 0.
  double b1 = 0.0, b2 = 0.0;
  glm::dvec3 position{0.0};
  // Unit geometric normal: triangles cross(v1 − v0, v2 − v0), spheres outward,
  // planes their stored normal. NOT flipped toward the ray: surfaces are
  // two-sided, the caller flips (dot(normal, d) > 0 ⇒ the ray hit the back).
  glm::dvec3 normal{0.0, 0.0, 1.0};
  // Unit interpolated vertex normal; equals `normal` when the mesh has none.
  glm::dvec3 shading_normal{0.0, 0.0, 1.0};
  glm::dvec2 uv{0.0};  // OBJ convention: v = 0 at the image's bottom (docs/surfaces.md)
  uint32_t material = 0;
};

// A ray origin moved off the surface along the geometric normal, far enough that
// the new ray cannot hit the surface it leaves (float positions; Wächter &
// Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
// Gems ch. 6). `n` is the geometric normal flipped to the side the ray leaves
// toward. The GLSL twin is offset_ray_origin() in shaders/bvh.glsl.
glm::dvec3 offset_ray_origin(const glm::dvec3& p, const glm::dvec3& n);

}  // namespace pyrolume::geometry
