// Data shared by the denoiser's shader (denoise.comp) and the host
// (host/denoise/Denoiser.cpp), in the common subset of GLSL and C++
// (shared/common.h), like shared/gpu_types.h.
#ifndef PYROLUME_DENOISE_TYPES_H
#define PYROLUME_DENOISE_TYPES_H

#include "shared/common.h"
#ifdef __cplusplus
namespace pyrolume::gpu {
#endif

PYRO_CONST uint DENOISE_WORKGROUP_SIZE = 8;

// Descriptor bindings of denoise.comp (set 0). One pixel per element, row 0 = top.
PYRO_CONST uint DENOISE_BINDING_COLOR_IN = 0;   // readonly vec4[]: premultiplied RGB, alpha
PYRO_CONST uint DENOISE_BINDING_VAR_IN = 1;     // readonly float[]: variance of the mean of the luminance
PYRO_CONST uint DENOISE_BINDING_COLOR_OUT = 2;  // writeonly vec4[]
PYRO_CONST uint DENOISE_BINDING_VAR_OUT = 3;    // writeonly float[]
// The first-hit features (image/Image.h Aovs) as the host packs them; one
// element each when the image has none. Two arrays rather than one struct of
// 32 bytes, so that each stays within lavapipe's 128 MiB storage-buffer range
// up to 3840×2160.
PYRO_CONST uint DENOISE_BINDING_NORMAL_DEPTH = 4;  // readonly vec4[]: normal (0 in media and misses), depth
PYRO_CONST uint DENOISE_BINDING_ALBEDO_DZ = 5;     // readonly vec4[]: albedo RGB; w: |∇depth| (larger central difference)
PYRO_CONST uint DENOISE_BINDING_VAR_BLURRED = 6;   // float[]: the 3×3 Gaussian of VAR_IN (the prefilter pass writes it)
// The guide (Aovs::guide, guide_alpha): readonly vec4[], RGB and alpha; one element when unused.
PYRO_CONST uint DENOISE_BINDING_GUIDE = 7;

// Which features denoise.comp uses (DenoiseConstants::flags).
PYRO_CONST uint DENOISE_USE_NORMAL_DEPTH = 1;
PYRO_CONST uint DENOISE_USE_ALBEDO = 2;
// The pass before each iteration: blur VAR_IN into VAR_BLURRED, nothing else.
PYRO_CONST uint DENOISE_PASS_PREFILTER = 4;
// The guided filter (docs/compositing.md "Denoiser"): the guide's relative
// difference and its alpha's difference join the weight (σ_g, τ_g, σ_ga in
// DenoiseConstants::guide_sigmas)...
PYRO_CONST uint DENOISE_USE_GUIDE = 8;
// ...and the features in the forms that measured best for it: normals
// compared by direction (their average over a pixel's samples is shorter
// where some samples met a medium first), depth by its relative difference,
// and a surface pixel never mixed with a medium or background one.
PYRO_CONST uint DENOISE_GUIDED_FEATURES = 16;
// A Gaussian blur of COLOR_IN into COLOR_OUT along x (step 1) or y (step 2),
// σ = guide_sigmas.w pixels, out to 2σ rounded up: the ratio estimator's
// window.
PYRO_CONST uint DENOISE_PASS_BLUR = 32;
// Pixels the pass leaves as they are (their colour and variance copied):
// those that are not surfaces (the surface layer's pass: its weights never mix
// a surface with anything else), and those whose colour and guide are all 0
// (nothing on the ray to filter). Both only save time.
PYRO_CONST uint DENOISE_ONLY_SURFACES = 64;
PYRO_CONST uint DENOISE_SKIP_EMPTY = 128;

// Push constants of one à-trous iteration.
struct DenoiseConstants {
  uvec4 size_step_flags;  // width, height, the tap spacing 2^i, DENOISE_USE_* bits
  vec4 sigmas;            // σ_l (luminance), σ_n (normal exponent), σ_z (depth), σ_a (albedo)
  vec4 guide_sigmas;      // σ_g, τ_g (guide), σ_ga (guide alpha), the blur's σ in pixels
};

#ifdef __cplusplus
static_assert(sizeof(DenoiseConstants) == 48);
PYRO_OFFSET(DenoiseConstants, sigmas, 16);
PYRO_OFFSET(DenoiseConstants, guide_sigmas, 32);
}  // namespace pyrolume::gpu
#endif
#endif
