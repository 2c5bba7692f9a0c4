// Structs and constants shared by the host (C++) and the shaders (GLSL): the one
// source of truth for data that crosses the boundary. Written in the common subset
// of both languages; only vec4/uvec4 members, so std140 and std430 agree and no
// vec3 padding can drift. The C++ side static_asserts every size below.
#ifndef PYROLUME_GPU_TYPES_H
#define PYROLUME_GPU_TYPES_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
namespace pyrolume::gpu {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using uint = uint32_t;
#define PYRO_CONST constexpr
#else
#define PYRO_CONST const
#endif

PYRO_CONST uint WORKGROUP_SIZE_X = 8;
PYRO_CONST uint WORKGROUP_SIZE_Y = 8;
PYRO_CONST uint MAX_MEDIA = 16;

// Descriptor bindings of render.comp (set 0).
PYRO_CONST uint BINDING_FRAME = 0;     // uniform FrameConstants
PYRO_CONST uint BINDING_MEDIA = 1;     // readonly buffer GpuMedium[]
PYRO_CONST uint BINDING_ACCUM = 2;     // buffer AccumTexel[] (one per pixel)

PYRO_CONST uint SHAPE_SPHERE = 0;
PYRO_CONST uint SHAPE_BOX = 1;

// One homogeneous medium (96 bytes).
struct GpuMedium {
  vec4 sigma_a;   // rgb: absorption coefficient, 1/unit; w: shape (SHAPE_*)
  vec4 sigma_s;   // rgb: scattering coefficient, 1/unit; w: Henyey–Greenstein g
  vec4 emission;  // rgb: sigma_a * Le, emitted radiance per unit length; w: unused
  vec4 bounds0;   // sphere: xyz centre, w radius; box: xyz min
  vec4 bounds1;   // box: xyz max
  vec4 reserved;
};

// Per-render constants (uniform buffer).
struct FrameConstants {
  vec4 camera_position;  // xyz; w: tan(fov_y / 2)
  vec4 camera_forward;   // xyz unit; w: aspect = width / height
  vec4 camera_right;     // xyz unit = normalize(cross(forward, up))
  vec4 camera_up;        // xyz unit = cross(right, forward)
  vec4 background;       // rgb radiance of escaping rays
  uvec4 image;           // x width, y height, z medium count, w max_depth
  uvec4 sampling;        // x seed, y frame, z unused, w unused
};

// Per-pass values (push constants).
struct PassConstants {
  uint sample_offset;  // index of this pass's first sample per pixel
  uint spp;            // samples per pixel in this pass
  uint pad0;
  uint pad1;
};

// Per-pixel accumulation, Kahan-compensated so float32 sums stay accurate over
// thousands of passes (Kahan 1965; `precise` stops the compiler reassociating).
struct AccumTexel {
  vec4 sum;       // rgb: Σ L; w: Σ real events (absorptions + scatterings)
  vec4 sum_c;     // compensation terms of sum
  vec4 sum_sq;    // rgb: Σ L²; w: Σ density lookups
  vec4 sum_sq_c;  // compensation terms of sum_sq; w: count of non-finite samples (plain sum)
};

#ifdef __cplusplus
static_assert(sizeof(GpuMedium) == 96);
static_assert(sizeof(FrameConstants) == 112);
static_assert(offsetof(FrameConstants, image) == 80);
static_assert(sizeof(PassConstants) == 16);
static_assert(sizeof(AccumTexel) == 64);
}  // namespace pyrolume::gpu
#endif
#undef PYRO_CONST
#endif
