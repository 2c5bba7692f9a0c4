#include "render/vulkan/SurfacePacking.h"

namespace pyrolume::geometry {

// The BVH builder's limits (geometry/Bvh.h) are the traversal's (bvh.glsl).
static_assert(kBvhStackSize == gpu::BVH_STACK_SIZE);
static_assert(kBvhMaxLeafTriangles == gpu::BVH_MAX_LEAF_TRIANGLES);

std::vector<gpu::GpuBvhNode> pack_gpu_nodes(const Bvh& bvh) {
  // Interior nodes keep their depth-first order; leaves fold into their parent.
  std::vector<uint32_t> gpu_index(bvh.nodes.size(), 0u);
  uint32_t interior = 0;
  for (size_t i = 0; i < bvh.nodes.size(); ++i)
    if (!bvh.nodes[i].is_leaf()) gpu_index[i] = interior++;
  // Child slot k (0, 1) of g: box c, and the GPU node `target` (interior) or c's triangles (leaf).
  auto set_child = [](gpu::GpuBvhNode& g, int k, const BvhNode& c, uint32_t target) {
    g.x[k] = c.bounds_min.x;
    g.y[k] = c.bounds_min.y;
    g.z[k] = c.bounds_min.z;
    g.x[2 + k] = c.bounds_max.x;
    g.y[2 + k] = c.bounds_max.y;
    g.z[2 + k] = c.bounds_max.z;
    (k == 0 ? g.child0 : g.child1) = c.is_leaf() ? c.offset : target;
    (k == 0 ? g.count0 : g.count1) = c.is_leaf() ? c.count : gpu::BVH_INTERIOR_CHILD;
  };
  if (bvh.nodes.empty() || bvh.nodes[0].is_leaf()) {
    // A root that is a leaf (or a Bvh never built): its triangles as child 0,
    // an empty leaf (no triangles to test) as child 1.
    BvhNode empty;
    empty.axis = BvhNode::kLeaf;
    gpu::GpuBvhNode root{};
    set_child(root, 0, bvh.nodes.empty() ? empty : bvh.nodes[0], 0u);
    set_child(root, 1, empty, 0u);
    return {root};
  }
  std::vector<gpu::GpuBvhNode> out(interior);
  for (size_t i = 0; i < bvh.nodes.size(); ++i) {
    if (bvh.nodes[i].is_leaf()) continue;
    const size_t first = i + 1, second = bvh.nodes[i].offset;
    set_child(out[gpu_index[i]], 0, bvh.nodes[first], gpu_index[first]);
    set_child(out[gpu_index[i]], 1, bvh.nodes[second], gpu_index[second]);
  }
  return out;
}

gpu::GpuSurfaceShape pack_gpu_shape(const SurfaceShape& s) {
  gpu::GpuSurfaceShape g{};
  g.center = gpu::vec3(s.center);
  g.material = s.material;
  if (s.type == SurfaceShape::Type::Sphere) {
    g.kind = gpu::SURFACE_SPHERE;
    g.radius = float(s.radius);
  } else {
    g.kind = gpu::SURFACE_PLANE;
    g.normal = gpu::vec3(s.normal);
    g.half_u = float(s.half_u);
    g.u_axis = gpu::vec3(s.u_axis);
    g.half_v = float(s.half_v);
  }
  return g;
}

GpuSurfaces pack_gpu_surfaces(const Surfaces& s) {
  GpuSurfaces g;
  g.nodes = pack_gpu_nodes(s.bvh);
  g.triangle_count = uint32_t(s.bvh.triangles.size());
  for (const Triangle& t : s.bvh.triangles) {
    gpu::GpuTriangle gt{};
    gt.v0 = t.p[0];
    gt.v1 = t.p[1];
    gt.v2 = t.p[2];
    g.triangles.push_back(gt);
    gpu::GpuTriangleAttributes a{};
    if (t.has_normals) {
      a.n0 = t.n[0];
      a.n1 = t.n[1];
      a.n2 = t.n[2];
    }
    if (t.has_uvs) {
      a.uv0 = t.uv[0];
      a.uv1 = t.uv[1];
      a.uv2 = t.uv[2];
    }
    a.material = t.material;
    a.source = t.source;
    a.mesh = t.mesh;
    a.flags = (t.has_normals ? gpu::TRIANGLE_HAS_NORMALS : 0u) | (t.has_uvs ? gpu::TRIANGLE_HAS_UVS : 0u);
    g.attributes.push_back(a);
  }
  if (g.triangles.empty()) {
    g.triangles.push_back({});
    g.attributes.push_back({});
  }
  g.shape_count = uint32_t(s.shapes.size());
  for (const SurfaceShape& shape : s.shapes) g.shapes.push_back(pack_gpu_shape(shape));
  if (g.shapes.empty()) g.shapes.push_back({});
  for (const Material& m : s.materials) {
    gpu::GpuMaterial gm{};
    gm.albedo = gpu::vec3(m.albedo);
    gm.texture_slot = m.texture < 0 ? gpu::NO_TEXTURE : uint32_t(m.texture);
    g.materials.push_back(gm);
  }
  if (g.materials.empty())
    g.materials.push_back({gpu::vec3(0.5f), gpu::NO_TEXTURE});
  return g;
}

}  // namespace pyrolume::geometry
