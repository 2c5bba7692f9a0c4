#version 460
// The preview's display pass: the progressive render's mean (Σ L / spp), scaled
// by the exposure, sRGB-encoded and packed to 8 bits per channel in the byte
// order of the swapchain image, letterboxed into the window. The host copies
// the result into the swapchain image with vkCmdCopyBufferToImage, which moves
// raw bytes: so the sRGB encode happens here whether the swapchain format is
// UNORM or SRGB (both present their bytes as sRGB-nonlinear values).
#extension GL_GOOGLE_include_directive : require

#include "shared/gpu_types.h"
#include "preview_shared.glsl"

layout(local_size_x = PREVIEW_WORKGROUP_SIZE, local_size_y = PREVIEW_WORKGROUP_SIZE) in;

layout(std430, set = 0, binding = PREVIEW_BINDING_ACCUM) readonly buffer AccumBlock { AccumTexel accum[]; };
layout(std430, set = 0, binding = PREVIEW_BINDING_DISPLAY) writeonly buffer DisplayBlock { uint display_texels[]; };
layout(push_constant) uniform DisplayBlockConstants { DisplayConstants dc; };

// IEC 61966-2-1, the same piecewise curve as srgb_encode() in host/image/ImageIo.cpp,
// so the window and `render -o out.png` show the same 8-bit values.
float srgb_encode(float L) {
  L = clamp(L, 0.0, 1.0);  // NaN clamps to 0 on lavapipe and most GPUs; the render counts non-finite samples as 0 anyway
  return L <= 0.0031308 ? 12.92 * L : 1.055 * pow(L, 1.0 / 2.4) - 0.055;
}

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  uvec2 target = dc.size.zw;
  if (p.x >= target.x || p.y >= target.y) return;

  vec3 srgb = dc.tone.yzw;
  uvec2 local = p - dc.rect.xy;  // wraps to huge values left of / above the rect
  if (local.x < dc.rect.z && local.y < dc.rect.w) {
    // Nearest texel: the preview shows samples, not a resampled image.
    uvec2 src = min(local * dc.size.xy / dc.rect.zw, dc.size.xy - 1u);
    vec3 L = accum[src.y * dc.size.x + src.x].sum.rgb * dc.tone.x;
    srgb = vec3(srgb_encode(L.r), srgb_encode(L.g), srgb_encode(L.b));
  }
  uvec3 b = uvec3(round(srgb * 255.0));
  if (dc.flags.x != 0u) b = b.bgr;
  display_texels[p.y * target.x + p.x] = b.x | (b.y << 8) | (b.z << 16) | (255u << 24);
}
