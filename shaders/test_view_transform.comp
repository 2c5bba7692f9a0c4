#version 460
// Test shader for tests/vulkan/view_transform_gpu_test.cpp: runs
// view_display() of shared/view_transform.h (what the preview's display
// shader runs) on a list of colours, so the GLSL build of the shared header
// can be compared with its C++ build (what PNG output runs).
#extension GL_GOOGLE_include_directive : require

#include "shared/view_transform.h"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint count; } pc;

struct ViewQuery {
  vec4 exposed;  // xyz: exposed scene-linear sRGB; w: the view (VIEW_AGX, VIEW_STANDARD, ...), as a float
  vec4 shown;    // out xyz: view_display(exposed, view); w: 0
};
layout(std430, binding = 0) buffer QueryBlock { ViewQuery queries[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  ViewQuery q = queries[i];
  q.shown = vec4(view_display(q.exposed.xyz, uint(q.exposed.w)), 0.0);
  queries[i] = q;
}
