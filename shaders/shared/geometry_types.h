// Surface data shared by the host (C++) and the shaders (GLSL): the BVH over
// triangles, the triangles themselves, analytic shapes and Lambertian
// materials. Same conventions as gpu_types.h: the common subset of both
// languages, only vec4/uvec4 members (std140 and std430 agree, no vec3
// padding), sizes static_asserted on the C++ side. Binding numbers are the
// includer's (render.comp's) to choose; docs/surfaces.md has the layout and
// the contract of shaders/bvh.glsl.
#ifndef PYROLUME_GEOMETRY_TYPES_H
#define PYROLUME_GEOMETRY_TYPES_H

#include "shared/common.h"
#ifdef __cplusplus
namespace pyrolume::gpu {
#endif

// Traversal keeps a fixed stack of this many node indices; the builder caps the
// leaf depth at BVH_STACK_SIZE - 1 so it can never overflow.
PYRO_CONST uint BVH_STACK_SIZE = 32;
PYRO_CONST uint BVH_MAX_LEAF_TRIANGLES = 4;
// GpuBvhNode::children.z/.w of a child that is an interior node (a leaf child
// holds its triangle count there, 0..BVH_MAX_LEAF_TRIANGLES).
PYRO_CONST uint BVH_INTERIOR_CHILD = 0xFFFFFFFFu;

// GpuSurfaceShape::info.x
PYRO_CONST uint SURFACE_SPHERE = 0;
PYRO_CONST uint SURFACE_PLANE = 1;

// GpuMaterial::info.x when the material has no albedo texture.
PYRO_CONST uint NO_TEXTURE = 0xFFFFFFFFu;

// GpuTriangleAttributes::info.w bits.
PYRO_CONST uint TRIANGLE_HAS_NORMALS = 1;
PYRO_CONST uint TRIANGLE_HAS_UVS = 2;

// One interior node of the GPU's BVH (64 bytes), holding the boxes of its two
// children, so that traversal tests both with one node read and one loop
// iteration (half the iterations of one box per node: llvmpipe runs each
// iteration for its whole SIMD group). Rows are (child 0 min, child 1 min,
// child 0 max, child 1 max) per axis: the slab test of both children is one
// vec4 expression per axis. Leaves are folded into their parents; node 0 is
// the root (a BVH that is a single leaf gets a root whose second child is an
// empty leaf). Depth-first order, so a subtree's nodes sit together.
struct GpuBvhNode {
  vec4 x;           // (min0.x, min1.x, max0.x, max1.x)
  vec4 y;           // (min0.y, min1.y, max0.y, max1.y)
  vec4 z;           // (min0.z, min1.z, max0.z, max1.z)
  uvec4 children;   // x, y: child 0, 1: its node index (interior) or first triangle (leaf);
                    // z, w: child 0, 1: BVH_INTERIOR_CHILD, or the leaf's triangle count
};

// The positions of one triangle (48 bytes), in BVH order: all traversal reads.
struct GpuTriangle {
  vec4 v0;  // xyz: vertex 0 in world space; w: unused
  vec4 v1;
  vec4 v2;
};

// What a closest hit needs besides the position (96 bytes), same index as
// GpuTriangle. Geometric normal = normalize(cross(v1 - v0, v2 - v0)).
struct GpuTriangleAttributes {
  vec4 n0;    // xyz: shading normal at vertex 0 (unit; zero without TRIANGLE_HAS_NORMALS)
  vec4 n1;
  vec4 n2;
  vec4 uv01;  // xy: uv of vertex 0, zw: uv of vertex 1 (OBJ convention: v = 0 is the image's bottom)
  vec4 uv2;   // xy: uv of vertex 2; zw: unused
  uvec4 info; // x: material index; y: the triangle's index before BVH reordering;
              // z: mesh index (scene order); w: TRIANGLE_HAS_* bits
};

// An analytic surface (64 bytes).
//   sphere: p0.xyz centre, p0.w radius.
//   plane:  p0.xyz centre point, p0.w half extent along u (<= 0: unbounded);
//           p1.xyz unit normal, p1.w half extent along v (<= 0: unbounded);
//           p2.xyz unit u axis (perpendicular to the normal); v axis = cross(normal, u).
struct GpuSurfaceShape {
  vec4 p0;
  vec4 p1;
  vec4 p2;
  uvec4 info;  // x: SURFACE_SPHERE or SURFACE_PLANE; y: material index; z, w: unused
};

// A Lambertian material (32 bytes): albedo = rgb × texture(uv) (texture
// linear RGB; 1 without a texture).
struct GpuMaterial {
  vec4 albedo;  // rgb: albedo factor in [0, 1]; w: unused
  uvec4 info;   // x: texture slot or NO_TEXTURE; y, z, w: unused
};

#ifdef __cplusplus
static_assert(sizeof(GpuBvhNode) == 64);
static_assert(offsetof(GpuBvhNode, children) == 48);
static_assert(sizeof(GpuTriangle) == 48);
static_assert(sizeof(GpuTriangleAttributes) == 96);
static_assert(offsetof(GpuTriangleAttributes, info) == 80);
static_assert(sizeof(GpuSurfaceShape) == 64);
static_assert(sizeof(GpuMaterial) == 32);
}  // namespace pyrolume::gpu
#endif
#endif
