// Data shared by the preview's display shader (preview_display.comp) and the
// host (host/preview/DisplayPass.cpp), in the common subset of GLSL and C++
// (shared/common.h), like shared/gpu_types.h.
#ifndef PYROLUME_PREVIEW_TYPES_H
#define PYROLUME_PREVIEW_TYPES_H

#include "shared/common.h"
#ifdef __cplusplus
namespace pyrolume::gpu {
#endif

PYRO_CONST uint PREVIEW_WORKGROUP_SIZE = 8;

// Descriptor bindings of preview_display.comp (set 0).
PYRO_CONST uint PREVIEW_BINDING_ACCUM = 0;    // readonly buffer AccumTexel[] (RenderSession's accumulation)
PYRO_CONST uint PREVIEW_BINDING_DISPLAY = 1;  // writeonly buffer uint[]: one packed 8-bit pixel per target texel

// Push constants of preview_display.comp.
struct DisplayConstants {
  uvec4 image_and_target;  // the render image's width, height; the target's (swapchain's) width, height
  uvec4 rect;              // the image in the target (letterboxed): left, top, width, height
  vec3 border;             // colour of the bars around the image (sRGB, 0..1)
  float radiance_scale;    // 2^exposure / spp: accumulated sum -> displayed linear radiance
  uint swap_red_blue;      // 1: the target stores B,G,R,A in memory
  uint view;               // VIEW_AGX, VIEW_STANDARD, ... (shared/view_transform.h)
  uint unused0, unused1;
};

#ifdef __cplusplus
static_assert(sizeof(DisplayConstants) == 64);
PYRO_OFFSET(DisplayConstants, rect, 16); PYRO_OFFSET(DisplayConstants, border, 32);
PYRO_OFFSET(DisplayConstants, radiance_scale, 44); PYRO_OFFSET(DisplayConstants, swap_red_blue, 48);
PYRO_OFFSET(DisplayConstants, view, 52); PYRO_OFFSET(DisplayConstants, unused0, 56);
PYRO_OFFSET(DisplayConstants, unused1, 60);
}  // namespace pyrolume::gpu
#endif
#endif
