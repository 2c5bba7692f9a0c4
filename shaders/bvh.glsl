// Ray queries against the scene's surfaces: a stack traversal of the BVH built
// by host/geometry/Bvh (lavapipe has no ray queries), a watertight two-sided
// ray/triangle test, and analytic spheres and planes. The CPU reference in
// host/geometry/ answers the same queries in double precision.
//
// Contract: before `#include "bvh.glsl"` the includer declares (binding
// numbers are its own; docs/surfaces.md):
//   #include "shared/geometry_types.h"
//   layout(std430, binding = …) readonly buffer BvhNodes      { GpuBvhNode bvh_nodes[]; };
//   layout(std430, binding = …) readonly buffer BvhTriangles  { GpuTriangle bvh_triangles[]; };
//   layout(std430, binding = …) readonly buffer BvhAttributes { GpuTriangleAttributes bvh_attributes[]; };
//   layout(std430, binding = …) readonly buffer SurfaceShapes { GpuSurfaceShape surface_shapes[]; };
//   const uint SURFACE_SHAPE_COUNT = …;   // may be a specialization constant
//   const bool SURFACE_HAS_TRIANGLES = …; // false: the BVH is never read
// Materials and textures are not read here: surface_interaction() returns
// the material index and uv for the includer to shade with.
#ifndef PYROLUME_BVH_GLSL
#define PYROLUME_BVH_GLSL

const uint SURFACE_HIT_TRIANGLE = 0u;
const uint SURFACE_HIT_SHAPE = 1u;

// What traversal finds; surface_interaction() expands it.
struct SurfaceHit {
  float t;         // ray parameter, units of |d|
  uint kind;       // SURFACE_HIT_TRIANGLE or SURFACE_HIT_SHAPE
  uint primitive;  // triangle index in BVH order (bvh_triangles[]), or shape index
  vec2 bary;       // barycentrics of vertices 1 and 2 (triangles)
};

struct SurfaceInteraction {
  vec3 position;
  vec3 normal;          // unit geometric normal, NOT flipped toward the ray (two-sided surfaces)
  vec3 shading_normal;  // unit; interpolated vertex normals, else = normal
  vec2 uv;              // OBJ convention: v = 0 at the image's bottom; sample texture(tex, vec2(u, 1 - v))
  uint material;
};

// Per-ray constants of the watertight test (Woop, Benthin & Wald 2013, JCGT
// 2(1)): the shear that maps the ray onto +z, as a matrix (same arithmetic as
// the paper's permute-and-shear; no dynamic component indexing).
struct TriangleRay {
  vec3 o;
  mat3 shear;  // p' = shear · (p − o); columns are GLSL's
};

TriangleRay make_triangle_ray(vec3 o, vec3 d) {
  vec3 a = abs(d);
  uint kz = (a.x > a.y) ? (a.x > a.z ? 0u : 2u) : (a.y > a.z ? 1u : 2u);
  uint kx = (kz + 1u) % 3u, ky = (kx + 1u) % 3u;
  if (d[kz] < 0.0) { uint s = kx; kx = ky; ky = s; }
  float Sz = 1.0 / d[kz];
  float Sx = d[kx] * Sz, Sy = d[ky] * Sz;
  // Rows: x' = p[kx] − Sx p[kz], y' = p[ky] − Sy p[kz], z' = Sz p[kz].
  mat3 m = mat3(0.0);
  m[kx][0] = 1.0; m[kz][0] = -Sx;
  m[ky][1] = 1.0; m[kz][1] = -Sy;
  m[kz][2] = Sz;
  TriangleRay r;
  r.o = o;
  r.shear = m;
  return r;
}

// Two-sided hit with 0 < t < t_max; t and (b1, b2) on success. `precise`
// keeps the compiler from fusing the edge functions differently for the two
// triangles that share an edge (that would reopen the cracks the test closes).
bool intersect_triangle(TriangleRay r, uint tri, float t_max, out float t, out vec2 bary) {
  t = 0.0;
  bary = vec2(0.0);
  GpuTriangle g = bvh_triangles[tri];
  precise vec3 A = r.shear * (g.v0 - r.o);
  precise vec3 B = r.shear * (g.v1 - r.o);
  precise vec3 C = r.shear * (g.v2 - r.o);
  precise float U = C.x * B.y - C.y * B.x;
  precise float V = A.x * C.y - A.y * C.x;
  precise float W = B.x * A.y - B.y * A.x;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  float det = U + V + W;
  if (det == 0.0) return false;  // the ray lies in the triangle's plane
  float T = U * A.z + V * B.z + W * C.z;
  float s = det < 0.0 ? -1.0 : 1.0;
  if (T * s <= 0.0 || T * s >= t_max * (det * s)) return false;
  float inv = 1.0 / det;
  t = T * inv;
  bary = vec2(V, W) * inv;
  return true;
}

// The reciprocal direction with components below 1e-30 replaced by ±1e-30:
// huge but finite slab distances, so 0·inf never makes a NaN (division by zero
// is not guaranteed to give inf in SPIR-V). The slabs stay right for boxes
// farther than ~1e-8 units from the origin along that axis, far below float's
// resolution at scene scale.
vec3 bvh_safe_inverse(vec3 d) {
  vec3 s = mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(d, vec3(0.0)));
  return 1.0 / mix(s, d, greaterThan(abs(d), vec3(1e-30)));
}

// Closest triangle with 0 < t < t_max; on success overwrites `hit`.
// any_hit = true stops at the first triangle found (shadow rays).
//
// Each node holds its two children's boxes (GpuBvhNode): one iteration tests
// both, runs the triangles of the hit leaf children (one loop for both, so
// the triangle test is one copy of code), descends into the nearer interior
// child and pushes the other with its entry distance; a popped entry that
// lies beyond the closest hit found since is skipped. llvmpipe runs every
// iteration for the whole SIMD group, so iterations are what cost: this
// visits half the nodes of a one-box-per-node traversal. No return inside
// the loop (docs/rendering.md "llvmpipe workarounds").
bool bvh_traverse(vec3 o, vec3 d, float t_max, bool any_hit, inout SurfaceHit hit) {
  TriangleRay r = make_triangle_ray(o, d);
  vec3 inv_d = bvh_safe_inverse(d);
  // The builder caps the leaf depth at BVH_STACK_SIZE − 1 and each level
  // pushes at most one node, so the stack cannot overflow.
  uint stack_node[BVH_STACK_SIZE];
  float stack_t[BVH_STACK_SIZE];
  uint sp = 0u, node = 0u;
  float t_closest = t_max;
  bool found = false;
  for (;;) {
    GpuBvhNode n = bvh_nodes[node];
    // Slab test of both boxes; the exit distance widened by 1 + 2γ(3) so float
    // rounding never drops a box whose triangle is hit (pbrt-v4 Bounds3::IntersectP).
    vec4 tx = (n.x - o.x) * inv_d.x, ty = (n.y - o.y) * inv_d.y, tz = (n.z - o.z) * inv_d.z;
    vec2 t_in = max(max(min(tx.xy, tx.zw), min(ty.xy, ty.zw)), max(min(tz.xy, tz.zw), vec2(0.0)));
    vec2 t_out = min(min(max(tx.xy, tx.zw), max(ty.xy, ty.zw)), min(max(tz.xy, tz.zw), vec2(t_closest))) * 1.0000004;
    bvec2 enter = lessThanEqual(t_in, t_out);
    // The hit leaf children's triangles: child 0's, then child 1's.
    uint tris0 = enter.x && n.count0 != BVH_INTERIOR_CHILD ? n.count0 : 0u;
    uint tris1 = enter.y && n.count1 != BVH_INTERIOR_CHILD ? n.count1 : 0u;
    for (uint k = 0u; k < tris0 + tris1; ++k) {
      uint i = k < tris0 ? n.child0 + k : n.child1 + (k - tris0);
      float t;
      vec2 bary;
      if (intersect_triangle(r, i, t_closest, t, bary)) {
        t_closest = t;
        found = true;
        hit.t = t;
        hit.kind = SURFACE_HIT_TRIANGLE;
        hit.primitive = i;
        hit.bary = bary;
        if (any_hit) break;
      }
    }
    if (any_hit && found) break;
    // Interior children still in reach (a leaf's hit may have moved t_closest).
    float t_reach = t_closest * 1.0000004;
    bool in0 = enter.x && n.count0 == BVH_INTERIOR_CHILD && t_in.x <= t_reach;
    bool in1 = enter.y && n.count1 == BVH_INTERIOR_CHILD && t_in.y <= t_reach;
    if (in0 && in1) {
      bool near1 = t_in.y < t_in.x;
      stack_node[sp] = near1 ? n.child0 : n.child1;
      stack_t[sp] = near1 ? t_in.x : t_in.y;
      ++sp;
      node = near1 ? n.child1 : n.child0;
    } else if (in0 || in1) {
      node = in0 ? n.child0 : n.child1;
    } else {
      bool popped = false;
      while (sp > 0u && !popped) {
        --sp;
        popped = stack_t[sp] <= t_reach;
        node = stack_node[sp];
      }
      if (!popped) break;
    }
  }
  return found;
}

bool bvh_closest_hit(vec3 o, vec3 d, float t_max, inout SurfaceHit hit) {
  return bvh_traverse(o, d, t_max, false, hit);
}

bool bvh_any_hit(vec3 o, vec3 d, float t_max) {
  SurfaceHit unused = SurfaceHit(0.0, 0u, 0u, vec2(0.0));
  return bvh_traverse(o, d, t_max, true, unused);
}

// Sphere or plane i with 0 < t < t_max (spheres: either root, so a ray from
// inside hits the inner side). Matches host/geometry/Shape.cpp.
bool intersect_surface_shape(uint i, vec3 o, vec3 d, float t_max, out float t) {
  t = 0.0;
  GpuSurfaceShape s = surface_shapes[i];
  if (s.kind == SURFACE_SPHERE) {
    // Stable quadratic (Ray Tracing Gems ch. 7) for a non-unit direction.
    vec3 oc = o - s.center;
    float a = dot(d, d);
    float b = dot(oc, d);
    vec3 perp = oc - (b / a) * d;
    float r = s.radius;
    float disc = a * (r * r - dot(perp, perp));
    if (disc < 0.0) return false;
    float q = -b - (b < 0.0 ? -1.0 : 1.0) * sqrt(disc);
    float t0 = q / a;
    float t1 = q != 0.0 ? (dot(oc, oc) - r * r) / q : -t0;
    float lo = min(t0, t1), hi = max(t0, t1);
    if (lo > 0.0 && lo < t_max) { t = lo; return true; }
    if (hi > 0.0 && hi < t_max) { t = hi; return true; }
    return false;
  }
  vec3 n = s.normal;
  float denom = dot(n, d);
  if (denom == 0.0) return false;
  float tp = dot(s.center - o, n) / denom;
  if (!(tp > 0.0 && tp < t_max)) return false;
  vec3 local = o + tp * d - s.center;
  vec3 v_axis = cross(n, s.u_axis);
  if (s.half_u > 0.0 && abs(dot(local, s.u_axis)) > s.half_u) return false;
  if (s.half_v > 0.0 && abs(dot(local, v_axis)) > s.half_v) return false;
  t = tp;
  return true;
}

// Closest surface (triangle or shape) with 0 < t < t_max.
bool intersect_surfaces(vec3 o, vec3 d, float t_max, out SurfaceHit hit) {
  hit.t = t_max;
  hit.kind = SURFACE_HIT_TRIANGLE;
  hit.primitive = 0u;
  hit.bary = vec2(0.0);
  bool found = false;
  if (SURFACE_HAS_TRIANGLES) found = bvh_closest_hit(o, d, t_max, hit);
  for (uint i = 0u; i < SURFACE_SHAPE_COUNT; ++i) {
    float t;
    if (intersect_surface_shape(i, o, d, hit.t, t)) {
      hit.t = t;
      hit.kind = SURFACE_HIT_SHAPE;
      hit.primitive = i;
      hit.bary = vec2(0.0);
      found = true;
    }
  }
  return found;
}

// Any surface with 0 < t < t_max (shadow rays: t_max just short of the light).
bool occluded_surfaces(vec3 o, vec3 d, float t_max) {
  for (uint i = 0u; i < SURFACE_SHAPE_COUNT; ++i) {
    float t;
    if (intersect_surface_shape(i, o, d, t_max, t)) return true;
  }
  if (SURFACE_HAS_TRIANGLES) return bvh_any_hit(o, d, t_max);
  return false;
}

const float SURFACE_INV_PI = 0.31830988618379067;

// Position, normals, uv and material of a hit (reads bvh_attributes[] once).
SurfaceInteraction surface_interaction(vec3 o, vec3 d, SurfaceHit hit) {
  SurfaceInteraction si;
  si.position = o + hit.t * d;
  if (hit.kind == SURFACE_HIT_TRIANGLE) {
    GpuTriangle g = bvh_triangles[hit.primitive];
    GpuTriangleAttributes a = bvh_attributes[hit.primitive];
    vec3 ng = cross(g.v1 - g.v0, g.v2 - g.v0);
    float len = length(ng);
    si.normal = len > 0.0 ? ng / len : vec3(0.0, 1.0, 0.0);
    float b0 = 1.0 - hit.bary.x - hit.bary.y;
    si.shading_normal = si.normal;
    if ((a.flags & TRIANGLE_HAS_NORMALS) != 0u) {
      vec3 ns = b0 * a.n0 + hit.bary.x * a.n1 + hit.bary.y * a.n2;
      float ls = length(ns);
      if (ls > 0.0) si.shading_normal = ns / ls;
    }
    si.uv = (a.flags & TRIANGLE_HAS_UVS) != 0u ? b0 * a.uv0 + hit.bary.x * a.uv1 + hit.bary.y * a.uv2 : vec2(0.0);
    si.material = a.material;
  } else {
    GpuSurfaceShape s = surface_shapes[hit.primitive];
    si.material = s.material;
    if (s.kind == SURFACE_SPHERE) {
      vec3 local = (si.position - s.center) / s.radius;
      si.normal = normalize(local);
      float phi = atan(local.z, local.x);
      if (phi < 0.0) phi += 2.0 / SURFACE_INV_PI;
      float theta = acos(clamp(si.normal.y, -1.0, 1.0));
      si.uv = vec2(phi * 0.5 * SURFACE_INV_PI, 1.0 - theta * SURFACE_INV_PI);
    } else {
      vec3 local = si.position - s.center;
      float a = dot(local, s.u_axis), b = dot(local, cross(s.normal, s.u_axis));
      si.normal = s.normal;
      si.uv = vec2(s.half_u > 0.0 ? a / (2.0 * s.half_u) + 0.5 : a, s.half_v > 0.0 ? b / (2.0 * s.half_v) + 0.5 : b);
    }
    si.shading_normal = si.normal;
  }
  return si;
}

// A ray origin moved off a surface along `n` (the geometric normal flipped to
// the side the new ray leaves toward) by a few float ulps, so the new ray
// cannot hit the surface it leaves (Wächter & Binder, Ray Tracing Gems ch. 6).
// Twin of geometry::offset_ray_origin on the host.
vec3 offset_ray_origin(vec3 p, vec3 n) {
  const float origin = 1.0 / 32.0, float_scale = 1.0 / 65536.0, int_scale = 256.0;
  ivec3 of_i = ivec3(int_scale * n);
  vec3 p_i = intBitsToFloat(floatBitsToInt(p) + mix(of_i, -of_i, lessThan(p, vec3(0.0))));
  return mix(p_i, p + float_scale * n, lessThan(abs(p), vec3(origin)));
}

#endif
