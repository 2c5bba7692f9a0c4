#version 460
// Per-pixel path tracing of emissive participating media, one progressive pass
// per dispatch. Homogeneous spheres/boxes and grid (vdb) media, delta tracking
// against per-cell majorants (a coarse grid walked by 3D DDA), the "absorption"
// or "collision" emission estimator, Henyey–Greenstein scattering; escaping
// paths see the background. With MIS, next-event estimation of the environment
// and the emissive grids at every scattering and surface vertex, combined with
// phase/BSDF sampling by the power heuristic (docs/mis.md).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require

#include "shared/gpu_types.h"
#include "rng.glsl"
#include "sampling.glsl"
#include "geometry.glsl"
#include "shared/geometry_types.h"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

#include "render_bindings.glsl"
#include "media.glsl"
#include "majorant_walk.glsl"
#include "surface_textures.glsl"
#include "light_sampling.glsl"
#include "camera.glsl"
#include "background.glsl"
#include "path_state.glsl"
#include "vertex.glsl"
#include "tracking.glsl"
#include "path.glsl"
#include "accumulation.glsl"

#include "wavefront.glsl"

void main() {
  if (WAVEFRONT_STAGE != WAVEFRONT_NONE) {
    wavefront_main();
    return;
  }
  uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, pass_constants.row_begin);
  uint width = frame.width, height = frame.height;
  if (pixel.x >= width || pixel.y >= min(height, pass_constants.row_end)) return;
  uint pixel_index = pixel.y * width + pixel.x;

  vec3 pass_sum = vec3(0.0), pass_sq = vec3(0.0);
  vec3 pass_sum_c = vec3(0.0), pass_sq_c = vec3(0.0);  // their Kahan compensations
  vec2 pass_alpha = vec2(0.0);                          // Σα, Σα²
  AovSums aovs = no_aovs();
  PathStats stats = PathStats(0.0, 0.0);
  float nonfinite = 0.0;
  const uint first = pass_constants.sample_offset, last = first + pass_constants.spp;
  uint k = first;  // the next sample: k < last after the loops means llvmpipe's loop budget ran out
  if (DEBUG_MODE != DEBUG_NONE) {
    for (; k < last; ++k) {
      uint rng;
      PathState p;
      camera_path(pixel, k, rng, p);
      vec3 T = transmittance(p.o, p.d, DEBUG_MODE == DEBUG_RATIO_TRACKING, rng, stats);
      pass_sum += T;
      pass_sq += T * T;
      pass_alpha += vec2(1.0 - avg3(T), (1.0 - avg3(T)) * (1.0 - avg3(T)));
    }
  } else {
    // Paths are regenerated within the lane: one loop iteration is one tracking
    // step, and a lane whose path ends starts its next sample at once instead of
    // idling until the longest path of its SIMD group ends (docs/rendering.md:
    // divergence halves throughput). Each sample keeps its own random stream, so
    // the result does not depend on the schedule.
    //
    // llvmpipe's loop budget (docs/rendering.md "llvmpipe workarounds"):
    // unfinished samples are reported below and the host redoes the pass in
    // smaller ones. (The nested loops are from when the limit was thought to
    // be per loop; they cost nothing.)
    // The guide, from the points its own dispatch marched before this pass.
    if (AOVS && first == 0u) add_pixel_guide(pixel, aovs);
    uint rng;
    PathState p;
    camera_path(pixel, k, rng, p);
    vec2 span[MEDIA_N];
    while (k < last) {
      for (uint n = 0u; n < 16384u && k < last; ++n) {
        if (!path_step(p, span, rng, stats)) continue;
        add_sample(p.L, p.alpha, pass_sum, pass_sum_c, pass_sq, pass_sq_c, pass_alpha, nonfinite);
        if (AOVS) add_sample_aovs(p, aovs);
        if (++k < last) camera_path(pixel, k, rng, p);
      }
    }
  }

  if (k < last) {  // the pass ran out of loop budget: the host discards and redoes it
    atomicAdd(pass_status.unfinished_samples, last - k);
    return;
  }

  add_pass(pixel_index, pass_sum, pass_sum_c, pass_sq, pass_sq_c, pass_alpha, stats, nonfinite);
  if (AOVS) add_pass_aovs(pixel_index, aovs);
}
