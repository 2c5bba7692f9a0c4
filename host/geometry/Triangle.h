#pragma once
// A triangle as the BVH stores it: float positions (what the GPU gets, so both
// sides test the very same triangle), per-vertex normals and uvs, a material.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "geometry/Mesh.h"
#include "geometry/Ray.h"

namespace pyrolume::geometry {

struct Triangle {
  std::array<glm::vec3, 3> p{};   // positions, world space
  std::array<glm::vec3, 3> n{};   // unit shading normals when has_normals
  std::array<glm::vec2, 3> uv{};  // when has_uvs; otherwise all zero
  uint32_t material = 0;
  uint32_t mesh = 0;    // which mesh of the scene it came from
  uint32_t source = 0;  // its index before BVH reordering
  bool has_normals = false, has_uvs = false;
};

// The mesh's triangles with `material` and `mesh_index`; `source` counts up from
// `first_source` (so several meshes can share one BVH with unique sources).
std::vector<Triangle> triangles_of(const Mesh& mesh, uint32_t material, uint32_t mesh_index, uint32_t first_source = 0);

// Per-ray constants of the watertight test.
struct TriangleRay {
  glm::dvec3 origin;
  int kx = 0, ky = 1, kz = 2;     // kz: the direction's dominant axis
  double Sx = 0, Sy = 0, Sz = 1;  // shear constants
  explicit TriangleRay(const Ray& ray);
};

// Watertight ray/triangle intersection (Woop, Benthin & Wald 2013, "Watertight
// Ray/Triangle Intersection", JCGT 2(1)), two-sided, in double precision.
// On a hit with 0 < t < t_max returns true and sets t and the barycentrics of
// vertices 1 and 2. A ray through a shared edge hits at least one of the two
// triangles.
bool intersect_triangle(const TriangleRay& ray, const Triangle& tri, double t_max, double& t, double& b1, double& b2);

// Fills the hit's normals, uv, material and position for a triangle hit
// (t, b1, b2 already set).
void finish_triangle_hit(const Triangle& tri, const Ray& ray, SurfaceHit& hit);

}  // namespace pyrolume::geometry
