#pragma once
// Everything a scene's surfaces need: the BVH over its triangles, analytic
// shapes, Lambertian materials and their albedo textures; closest-hit and
// shadow queries over all of them. Their GPU layout is
// render/vulkan/SurfacePacking.h.
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "geometry/Bvh.h"
#include "geometry/Ray.h"
#include "geometry/Shape.h"
#include "geometry/Texture.h"

namespace pyrolume::geometry {

// Lambertian: albedo(uv) = albedo × texture(uv) (× 1 without a texture).
struct Material {
  glm::dvec3 albedo{0.5};
  int texture = -1;  // index into Surfaces::textures, or −1
};

struct Surfaces {
  Bvh bvh;
  std::vector<SurfaceShape> shapes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  bool empty() const { return bvh.triangles.empty() && shapes.empty(); }
};

// Closest triangle or shape with 0 < t < t_max (hit.kind says which;
// hit.primitive is the triangle's BVH index or the shape's index).
bool intersect(const Surfaces& surfaces, const Ray& ray, double t_max, SurfaceHit& hit);
// Any surface with 0 < t < t_max.
bool occluded(const Surfaces& surfaces, const Ray& ray, double t_max);
// The hit material's albedo at the hit's uv.
glm::dvec3 albedo_at(const Surfaces& surfaces, const SurfaceHit& hit);

}  // namespace pyrolume::geometry
