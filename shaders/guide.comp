#version 460
// The denoiser's guide (film.aovs; docs/compositing.md "The guide"): once per
// render, before the first pass, the guide's march (guide.glsl) at every
// pixel corner and pixel centre, into guide_points; the first pass combines
// each pixel's five (accumulation.glsl add_pixel_guide). A pipeline of its
// own, specialised like render.comp's: in the paths' pipeline the march's
// code, even where no pass ran it, made the paths ~25 % slower on llvmpipe
// (docs/benchmarks.md "The guide's cost").
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
#include "camera.glsl"
#include "background.glsl"
#include "guide.glsl"

vec4 guide_ray(uvec2 pixel, vec2 film) {
  vec3 L, T;
  guide_march(frame.camera_position, camera_direction(pixel, film), L, T);
  return vec4(L, 1.0 - avg3(T));
}

// One lane per corner, the corner (x, y) being pixel (x, y)'s top-left one,
// x ≤ width, y ≤ height; a lane whose corner is a pixel's also marches that
// pixel's centre (where each goes: render_bindings.glsl guide_corner_index,
// guide_centre_index). A dispatch marches the corner rows row_begin ≤ y <
// row_end (PassConstants).
void main() {
  const uvec2 corner = gl_GlobalInvocationID.xy + uvec2(0u, pass_constants.row_begin);
  const uint width = frame.width, height = frame.height;
  if (corner.x > width || corner.y > height || corner.y >= pass_constants.row_end) return;
  guide_points[guide_corner_index(corner)] = guide_ray(corner, vec2(0.0));
  if (corner.x < width && corner.y < height) guide_points[guide_centre_index(corner)] = guide_ray(corner, vec2(0.5));
}
