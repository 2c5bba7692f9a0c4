#pragma once
// A bounding volume hierarchy over triangles: binned SAH build (Wald 2007, "On
// fast Construction of SAH-based Bounding Volume Hierarchies"), flattened in
// depth-first order, and a plain stack traversal for the CPU reference (the
// GPU reads the same tree with its leaves folded into their parents:
// pack_gpu_nodes in render/vulkan/SurfacePacking.h, shaders/bvh.glsl).
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "geometry/Ray.h"
#include "geometry/Triangle.h"

namespace pyrolume::geometry {

// The GPU traversal's fixed stack and leaf size (shaders/shared/geometry_types.h
// BVH_STACK_SIZE, BVH_MAX_LEAF_TRIANGLES; SurfacePacking.cpp asserts they agree).
inline constexpr uint32_t kBvhStackSize = 32;
inline constexpr uint32_t kBvhMaxLeafTriangles = 4;

struct BvhNode {
  static constexpr uint32_t kLeaf = 3;  // `axis` of a leaf
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};
  uint32_t offset = 0;  // interior: index of the second child (the first is this + 1); leaf: first triangle
  uint32_t count = 0;   // leaf: triangles (0 only in the empty BVH's root); interior: 0
  uint32_t axis = 0;    // interior: split axis 0..2; leaf: kLeaf
  bool is_leaf() const { return axis == kLeaf; }
};

enum class BvhSplit {
  Sah,     // binned surface area heuristic (the default)
  Median,  // object median on the widest centroid axis (a baseline for tests)
};

struct BvhOptions {
  BvhSplit split = BvhSplit::Sah;
  int bins = 16;               // SAH bins per axis
  uint32_t max_leaf_size = 4;  // ≤ kBvhMaxLeafTriangles
};

struct Bvh {
  std::vector<BvhNode> nodes;       // nodes[0] is the root; never empty
  std::vector<Triangle> triangles;  // reordered so every leaf owns a contiguous range
  uint32_t depth = 0;               // deepest leaf (root = 0); < kBvhStackSize
};

// Builds over `triangles` (moved in, reordered; Triangle::source keeps each
// one's original index). Zero triangles give a single empty leaf. Leaves hold
// at most max_leaf_size triangles; the depth never exceeds kBvhStackSize − 1
// (deeper subtrees switch to median splits), so the GPU's fixed stack suffices.
Bvh build_bvh(std::vector<Triangle> triangles, const BvhOptions& options = {});

// Closest triangle with 0 < t < t_max: fills `hit` (t, primitive = index in
// bvh.triangles, barycentrics, normals, uv, material) and returns true.
bool intersect(const Bvh& bvh, const Ray& ray, double t_max, SurfaceHit& hit);
// Any triangle with 0 < t < t_max (shadow rays); stops at the first found.
bool occluded(const Bvh& bvh, const Ray& ray, double t_max);

// The same answers by testing every triangle (for tests). Ties in t go to the
// lower index in `triangles`.
bool intersect_brute_force(const std::vector<Triangle>& triangles, const Ray& ray, double t_max, SurfaceHit& hit);
bool occluded_brute_force(const std::vector<Triangle>& triangles, const Ray& ray, double t_max);

// Expected cost of a random ray that hits the root box, with traversal and
// intersection costs 1 (MacDonald & Booth 1990): Σ_interior A(n)/A(root) +
// Σ_leaf A(n)/A(root)·count. Lower is better; a single leaf costs N.
double sah_cost(const Bvh& bvh);

}  // namespace pyrolume::geometry
