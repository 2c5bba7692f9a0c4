// Surface data shared by the host (C++) and the shaders (GLSL): the BVH over
// triangles, the triangles themselves, analytic shapes and Lambertian
// materials. Same conventions as gpu_types.h: the common subset of both
// languages, vec4 members or a vec3 and a 4-byte scalar per 16 bytes (and
// vec2s at multiples of 8), every size and offset static_asserted. Binding
// numbers are the includer's (render.comp's) to choose; docs/surfaces.md has
// the layout and the contract of shaders/bvh.glsl.
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
// GpuBvhNode count0/count1 of a child that is an interior node (a leaf child
// holds its triangle count there, 0..BVH_MAX_LEAF_TRIANGLES).
PYRO_CONST uint BVH_INTERIOR_CHILD = 0xFFFFFFFFu;

// GpuSurfaceShape::kind
PYRO_CONST uint SURFACE_SPHERE = 0;
PYRO_CONST uint SURFACE_PLANE = 1;

// GpuMaterial::texture_slot when the material has no albedo texture.
PYRO_CONST uint NO_TEXTURE = 0xFFFFFFFFu;

// GpuTriangleAttributes::flags bits.
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
  vec4 x;       // (min0.x, min1.x, max0.x, max1.x)
  vec4 y;       // (min0.y, min1.y, max0.y, max1.y)
  vec4 z;       // (min0.z, min1.z, max0.z, max1.z)
  uint child0;  // child 0: its node index (interior) or its first triangle (leaf)
  uint child1;  // child 1: the same
  uint count0;  // child 0: BVH_INTERIOR_CHILD, or its leaf's triangle count
  uint count1;  // child 1: the same
};

// The positions of one triangle (48 bytes), in BVH order: all traversal reads.
struct GpuTriangle {
  vec3 v0;  // vertex 0 in world space
  float unused0;
  vec3 v1;
  float unused1;
  vec3 v2;
  float unused2;
};

// What a closest hit needs besides the position (80 bytes), same index as
// GpuTriangle. Geometric normal = normalize(cross(v1 - v0, v2 - v0)).
struct GpuTriangleAttributes {
  vec3 n0;        // shading normal at vertex 0 (unit; zero without TRIANGLE_HAS_NORMALS)
  uint material;  // index into the materials
  vec3 n1;
  uint source;    // the triangle's index before BVH reordering
  vec3 n2;
  uint mesh;      // its mesh's index (scene order)
  vec2 uv0;       // uv of vertex 0 (OBJ convention: v = 0 is the image's bottom)
  vec2 uv1;
  vec2 uv2;
  uint flags;     // TRIANGLE_HAS_* bits
  uint unused;
};

// An analytic surface (64 bytes): a sphere or a plane (kind).
struct GpuSurfaceShape {
  vec3 center;    // sphere: centre; plane: its centre point (uv origin)
  float radius;   // sphere
  vec3 normal;    // plane: unit normal
  float half_u;   // plane: half extent along u_axis (<= 0: unbounded)
  vec3 u_axis;    // plane: unit, perpendicular to the normal; v axis = cross(normal, u_axis)
  float half_v;   // plane: half extent along v (<= 0: unbounded)
  uint kind;      // SURFACE_SPHERE or SURFACE_PLANE
  uint material;  // index into the materials
  uint unused0, unused1;
};

// A Lambertian material (16 bytes): albedo = albedo × texture(uv) (texture
// linear RGB; 1 without a texture).
struct GpuMaterial {
  vec3 albedo;        // albedo factor in [0, 1]
  uint texture_slot;  // its albedo texture, or NO_TEXTURE
};

#ifdef __cplusplus
// Every field where std430 puts it (a vec3 ends 4 bytes before the next 16).
static_assert(sizeof(GpuBvhNode) == 64);
PYRO_OFFSET(GpuBvhNode, y, 16); PYRO_OFFSET(GpuBvhNode, z, 32); PYRO_OFFSET(GpuBvhNode, child0, 48);
PYRO_OFFSET(GpuBvhNode, child1, 52); PYRO_OFFSET(GpuBvhNode, count0, 56); PYRO_OFFSET(GpuBvhNode, count1, 60);
static_assert(sizeof(GpuTriangle) == 48);
PYRO_OFFSET(GpuTriangle, unused0, 12); PYRO_OFFSET(GpuTriangle, v1, 16); PYRO_OFFSET(GpuTriangle, unused1, 28);
PYRO_OFFSET(GpuTriangle, v2, 32); PYRO_OFFSET(GpuTriangle, unused2, 44);
static_assert(sizeof(GpuTriangleAttributes) == 80);
PYRO_OFFSET(GpuTriangleAttributes, material, 12); PYRO_OFFSET(GpuTriangleAttributes, n1, 16);
PYRO_OFFSET(GpuTriangleAttributes, source, 28); PYRO_OFFSET(GpuTriangleAttributes, n2, 32);
PYRO_OFFSET(GpuTriangleAttributes, mesh, 44); PYRO_OFFSET(GpuTriangleAttributes, uv0, 48);
PYRO_OFFSET(GpuTriangleAttributes, uv1, 56); PYRO_OFFSET(GpuTriangleAttributes, uv2, 64);
PYRO_OFFSET(GpuTriangleAttributes, flags, 72); PYRO_OFFSET(GpuTriangleAttributes, unused, 76);
static_assert(sizeof(GpuSurfaceShape) == 64);
PYRO_OFFSET(GpuSurfaceShape, radius, 12); PYRO_OFFSET(GpuSurfaceShape, normal, 16);
PYRO_OFFSET(GpuSurfaceShape, half_u, 28); PYRO_OFFSET(GpuSurfaceShape, u_axis, 32);
PYRO_OFFSET(GpuSurfaceShape, half_v, 44); PYRO_OFFSET(GpuSurfaceShape, kind, 48);
PYRO_OFFSET(GpuSurfaceShape, material, 52); PYRO_OFFSET(GpuSurfaceShape, unused0, 56);
PYRO_OFFSET(GpuSurfaceShape, unused1, 60);
static_assert(sizeof(GpuMaterial) == 16);
PYRO_OFFSET(GpuMaterial, texture_slot, 12);
}  // namespace pyrolume::gpu
#endif
#endif
