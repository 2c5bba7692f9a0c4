#version 460
// Test shader for tests/vulkan/light_gpu_test.cpp: runs every function of
// lights.glsl on a list of queries so the results can be compared with
// host/light/EnvironmentMap and host/light/EmissionCdf.
#extension GL_GOOGLE_include_directive : require

#include "shared/light_types.h"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint count; } pc;

layout(std140, binding = 0) uniform LightBlock {
  GpuEnvironment env;
  GpuEmissionCdf emission;
};
layout(std430, binding = 1) readonly buffer EnvTexelBlock { vec4 env_texels[]; };
layout(std430, binding = 2) readonly buffer EnvCdfBlock { float env_cdf[]; };
layout(std430, binding = 3) readonly buffer EmissionCdfBlock { float emission_cdf[]; };
layout(std430, binding = 4) readonly buffer EmissionCellBlock { uint emission_cells[]; };
layout(std430, binding = 5) readonly buffer EmissionPmfBlock { float emission_pmf[]; };
layout(std430, binding = 7) readonly buffer EmissionClusterBlock { GpuEmissionCluster emission_clusters[]; };

#define LIGHTS_ENVIRONMENT
#define LIGHTS_EMISSION
#include "lights.glsl"

struct Query {
  vec4 u;       // xy: env_sample u2; z: emission_sample u; w: its u_cell
  vec4 u3;      // xyz: emission_sample u3
  vec4 env_dir; // xyz: a direction for env_radiance / env_pdf
  vec4 dir;     // xyz: a direction for emission_direction_pdf from o;
                // w: the distance from o along it to a point for emission_pdf
  vec4 point;   // xyz: the receiver o of the emission functions; out w: emission_receiver_norm(o)
  vec4 env_s;   // out: sampled dir, pdf
  vec4 env_r;   // out: sampled radiance; w: env_pdf(sampled dir)
  vec4 env_q;   // out: env_radiance(dir); w: env_pdf(dir)
  vec4 em_s;    // out: point sampled from o, pdf
  vec4 em_q;    // out: x: cell (bits), y: emission_pdf(sampled point), z: emission_pdf(o + dir.w·dir),
                // w: emission_direction_pdf(o, dir)
};
layout(std430, binding = 6) buffer QueryBlock { Query queries[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  Query q = queries[i];
  EnvSample es = env_sample(env, q.u.xy);
  q.env_s = vec4(es.dir, es.pdf);
  q.env_r = vec4(es.radiance, env_pdf(env, es.dir));
  q.env_q = vec4(env_radiance(env, q.env_dir.xyz), env_pdf(env, q.env_dir.xyz));
  vec3 o = q.point.xyz;
  float norm = emission_receiver_norm(emission, o);
  q.point.w = norm;
  EmissionSample ms = emission_sample(emission, o, norm, q.u.z, q.u.w, q.u3.xyz);
  q.em_s = vec4(ms.p, ms.pdf);
  q.em_q = vec4(uintBitsToFloat(ms.cell), emission_pdf(emission, o, norm, ms.p),
                emission_pdf(emission, o, norm, o + q.dir.w * q.dir.xyz), emission_direction_pdf(emission, o, norm, q.dir.xyz));
  queries[i] = q;
}
