#version 460
// Test shader for tests/vulkan/vk_context_test.cpp: exercises a specialization
// constant, a push-constant block, an SSBO, a 3D and a 1D sampled image.
layout(local_size_x = 64) in;

layout(constant_id = 0) const uint MULTIPLIER = 1;

layout(push_constant) uniform Push {
  uint count;         // values[] to fill
  uint offset;        // added to each value
  uint sample_count;  // samples[] to evaluate
} pc;

layout(std430, binding = 0) writeonly buffer Values { uint values[]; };
layout(binding = 1) uniform sampler3D grid;
layout(binding = 2) uniform sampler1D table;
struct Sample {
  vec4 coord;   // xyz: grid coordinate in [0,1]^3, w: table coordinate
  vec4 result;  // x: grid, y/z: table r/g
};
layout(std430, binding = 3) buffer Samples { Sample samples[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < pc.count) values[i] = i * MULTIPLIER + pc.offset;
  if (i < pc.sample_count) {
    vec4 c = samples[i].coord;
    vec4 t = textureLod(table, c.w, 0.0);
    samples[i].result = vec4(textureLod(grid, c.xyz, 0.0).r, t.r, t.g, 0.0);
  }
}
