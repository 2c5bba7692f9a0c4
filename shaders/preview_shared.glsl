// Data shared by the preview's display shader (preview_display.comp) and the
// host (host/preview/DisplayPass.cpp): one declaration, included by both, in the
// common subset of GLSL and C++ like shared/gpu_types.h (only vec4/uvec4 members).
#ifndef PYROLUME_PREVIEW_SHARED_GLSL
#define PYROLUME_PREVIEW_SHARED_GLSL

#ifdef __cplusplus
#include "shared/gpu_types.h"
namespace pyrolume::gpu {
#define PREVIEW_CONST constexpr
#else
#define PREVIEW_CONST const
#endif

PREVIEW_CONST uint PREVIEW_WORKGROUP_SIZE = 8;

// Descriptor bindings of preview_display.comp (set 0).
PREVIEW_CONST uint PREVIEW_BINDING_ACCUM = 0;    // readonly buffer AccumTexel[] (RenderSession's accumulation)
PREVIEW_CONST uint PREVIEW_BINDING_DISPLAY = 1;  // writeonly buffer uint[]: one packed 8-bit pixel per target texel

// Push constants of preview_display.comp.
struct DisplayConstants {
  uvec4 size;   // x, y: render image size; z, w: target (swapchain) size
  uvec4 rect;   // x, y: top-left of the image in the target; z, w: its size there (letterboxed)
  vec4 tone;    // x: 2^exposure / spp (accumulated sum -> displayed linear radiance); yzw: border colour (sRGB, 0..1)
  uvec4 flags;  // x: 1 = the target stores B,G,R,A in memory (swap red and blue);
                // y: the view, VIEW_AGX or VIEW_STANDARD (shared/view_transform.h); zw: unused
};

#ifdef __cplusplus
static_assert(sizeof(DisplayConstants) == 64);
}  // namespace pyrolume::gpu
#endif
#undef PREVIEW_CONST
#endif
