#pragma once
// Everything a scene's surfaces need: the BVH over its triangles, analytic
// shapes, Lambertian materials and their albedo textures; closest-hit and
// shadow queries over all of them; and the GPU packing (geometry_types.h).
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "geometry/Bvh.h"
#include "geometry/Ray.h"
#include "geometry/Shape.h"
#include "geometry/Texture.h"
#include "shared/geometry_types.h"

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

// The buffers of shaders/bvh.glsl, each at least one element long (Vulkan has
// no empty buffers): an empty BVH is a root with two empty leaves plus one dummy
// triangle; no shapes gives one dummy shape (SURFACE_SHAPE_COUNT = 0 keeps the
// shader from reading it); no materials gives one grey material.
struct GpuSurfaces {
  std::vector<gpu::GpuBvhNode> nodes;
  std::vector<gpu::GpuTriangle> triangles;
  std::vector<gpu::GpuTriangleAttributes> attributes;
  std::vector<gpu::GpuSurfaceShape> shapes;
  std::vector<gpu::GpuMaterial> materials;
  uint32_t shape_count = 0;     // the real number of shapes (SURFACE_SHAPE_COUNT)
  uint32_t triangle_count = 0;  // the real number of triangles
};

GpuSurfaces pack_gpu_surfaces(const Surfaces& surfaces);
// The parts on their own (the test shader uses them without materials).
std::vector<gpu::GpuBvhNode> pack_gpu_nodes(const Bvh& bvh);
gpu::GpuSurfaceShape pack_gpu_shape(const SurfaceShape& shape);

}  // namespace pyrolume::geometry
