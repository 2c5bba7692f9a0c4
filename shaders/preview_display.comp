#version 460
// The preview's display pass: the progressive render's mean (Σ L / spp), scaled
// by the exposure, through the view transform (film.view, with its sRGB
// encode: shared/view_transform.h, the code PNG output runs too) and packed to
// 8 bits per channel in the byte order of the swapchain image, letterboxed
// into the window. The host copies the result into the swapchain image with
// vkCmdCopyBufferToImage, which moves raw bytes: so the sRGB encode happens
// here whether the swapchain format is UNORM or SRGB (both present their bytes
// as sRGB-nonlinear values).
#extension GL_GOOGLE_include_directive : require

#include "shared/gpu_types.h"
#include "shared/preview_types.h"
#include "shared/view_transform.h"

layout(local_size_x = PREVIEW_WORKGROUP_SIZE, local_size_y = PREVIEW_WORKGROUP_SIZE) in;

layout(std430, set = 0, binding = PREVIEW_BINDING_ACCUM) readonly buffer AccumBlock { AccumTexel accum[]; };
layout(std430, set = 0, binding = PREVIEW_BINDING_DISPLAY) writeonly buffer DisplayBlock { uint display_texels[]; };
layout(push_constant) uniform DisplayBlockConstants { DisplayConstants dc; };

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  uvec2 target = dc.image_and_target.zw;
  if (p.x >= target.x || p.y >= target.y) return;

  vec3 srgb = dc.border;
  uvec2 local = p - dc.rect.xy;  // wraps to huge values left of / above the rect
  if (local.x < dc.rect.z && local.y < dc.rect.w) {
    // Nearest texel: the preview shows samples, not a resampled image.
    uvec2 src = min(local * dc.image_and_target.xy / dc.rect.zw, dc.image_and_target.xy - 1u);
    vec3 L = accum[src.y * dc.image_and_target.x + src.x].sum * dc.radiance_scale;
    srgb = view_display(L, dc.view);
  }
  uvec3 b = uvec3(round(srgb * 255.0));
  if (dc.swap_red_blue != 0u) b = b.bgr;
  display_texels[p.y * target.x + p.x] = b.x | (b.y << 8) | (b.z << 16) | (255u << 24);
}
