#pragma once
// A scene's surfaces (geometry/Surfaces.h) in the GPU's layout
// (shaders/shared/geometry_types.h).
#include <cstdint>
#include <vector>

#include "geometry/Surfaces.h"
#include "shared/geometry_types.h"

namespace pyrolume::geometry {

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
