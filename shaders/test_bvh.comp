#version 460
// Test shader for tests/vulkan/bvh_gpu_test.cpp: one ray per invocation through
// shaders/bvh.glsl, closest hit and shadow query, written back for comparison
// with the CPU traversal (host/geometry/Bvh).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shared/geometry_types.h"

layout(constant_id = 0) const uint SURFACE_SHAPE_COUNT = 0;
layout(constant_id = 1) const bool SURFACE_HAS_TRIANGLES = true;

layout(push_constant) uniform Push {
  uint ray_count;
} pc;

layout(std430, binding = 0) readonly buffer BvhNodes { GpuBvhNode bvh_nodes[]; };
layout(std430, binding = 1) readonly buffer BvhTriangles { GpuTriangle bvh_triangles[]; };
layout(std430, binding = 2) readonly buffer BvhAttributes { GpuTriangleAttributes bvh_attributes[]; };
layout(std430, binding = 3) readonly buffer SurfaceShapes { GpuSurfaceShape surface_shapes[]; };

#include "bvh.glsl"

struct TestRay {
  vec4 origin;     // xyz; w: t_max
  vec4 direction;  // xyz (not necessarily unit)
};
struct TestResult {
  vec4 hit;      // x: t (0 on a miss), yz: barycentrics, w: 1 when occluded_surfaces() said so
  uvec4 id;      // x: 1 + kind (0 = miss), y: primitive, z: material, w: 0
  vec4 normal;   // xyz: geometric normal; w: 0
  vec4 shading;  // xyz: shading normal; w: 0
  vec4 uv;       // xy: uv; zw: offset_ray_origin(position, normal).xy
};
layout(std430, binding = 4) readonly buffer Rays { TestRay rays[]; };
layout(std430, binding = 5) writeonly buffer Results { TestResult results[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.ray_count) return;
  vec3 o = rays[i].origin.xyz, d = rays[i].direction.xyz;
  float t_max = rays[i].origin.w;
  TestResult r;
  r.hit = vec4(0.0);
  r.id = uvec4(0u);
  r.normal = vec4(0.0);
  r.shading = vec4(0.0);
  r.uv = vec4(0.0);
  SurfaceHit hit;
  if (intersect_surfaces(o, d, t_max, hit)) {
    SurfaceInteraction si = surface_interaction(o, d, hit);
    r.hit.xyz = vec3(hit.t, hit.bary);
    r.id.xyz = uvec3(1u + hit.kind, hit.primitive, si.material);
    r.normal.xyz = si.normal;
    r.shading.xyz = si.shading_normal;
    r.uv = vec4(si.uv, offset_ray_origin(si.position, si.normal).xy);
  }
  r.hit.w = occluded_surfaces(o, d, t_max) ? 1.0 : 0.0;
  results[i] = r;
}
