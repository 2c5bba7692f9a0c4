#version 460
// The bare lookup loop of tools/bench_lookup.cpp: the machine's ceiling for
// density lookups, against which the renderer's lookups/s are judged
// (docs/benchmarks.md). Each invocation is a random walk through a noise
// volume: one trilinear R16F lookup per step, and the step length depends on
// the value just read (dependent, like delta tracking). Nothing else: no
// majorant, no events, no divergence (every walk takes `steps` steps).
#extension GL_GOOGLE_include_directive : require
#include "rng.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
  uint width;  // invocations per row
  uint steps;  // lookups per invocation
  uint seed;
  float step_texels;  // mean step length, in texels
} pc;

layout(binding = 0) uniform sampler3D noise;
layout(std430, binding = 1) writeonly buffer Out { float sums[]; };

void main() {
  const uint id = gl_GlobalInvocationID.y * pc.width + gl_GlobalInvocationID.x;
  uint rng = rng_init(pc.seed, 0u, id, 0u);
  const float texel = 1.0 / float(textureSize(noise, 0).x);
  vec3 p = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
  const float z = 2.0 * rng_next(rng) - 1.0, phi = 6.2831853 * rng_next(rng);
  const float r = sqrt(max(0.0, 1.0 - z * z));
  const vec3 d = vec3(r * cos(phi), r * sin(phi), z) * (pc.step_texels * texel);
  float sum = 0.0;
  for (uint i = 0u; i < pc.steps; ++i) {
    const float v = textureLod(noise, p, 0.0).r;
    sum += v;
    // A free flight with rate v (v in [0.5, 1)): step length -ln(1 - u)/v.
    p = fract(p + d * (-log(1.0 - rng_next(rng)) / v));
  }
  sums[id] = sum;  // keeps the loop alive
}
