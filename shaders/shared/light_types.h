// Light-sampling structs shared by the host (C++) and the shaders (GLSL): the
// environment map and the emission CDF of an emissive grid medium
// (docs/lights.md; host/light/EnvironmentMap, host/light/EmissionCdf;
// shaders/lights.glsl). Same rules as gpu_types.h: written in the common subset
// of both languages, only vec4/uvec4 members (std140 and std430 agree), every
// size static_asserted. Binding numbers are the includer's (render.comp's
// BINDING_* live in gpu_types.h).
#ifndef PYROLUME_LIGHT_TYPES_H
#define PYROLUME_LIGHT_TYPES_H

#include "shared/common.h"
#ifdef __cplusplus
namespace pyrolume::gpu {
#endif

// A lat-long environment map (32 bytes). +Z up, Blender's equirectangular
// convention: map direction (sinθ cosφ, sinθ sinφ, cosθ) with θ = π·v, φ = π − 2π·u,
// v = 0 the top row. World direction d is looked up at Rz(−rotation)·d.
// Buffers (names the includer declares, see lights.glsl):
//   env_texels[W·H]: vec4(r, g, b, p_uv), row 0 = top; p_uv = the piecewise-constant
//                    (u, v) sampling density of that texel; radiance = rgb × scale.
//   env_cdf[(H + 1) + H·(W + 1)]: marginal CDF over rows, then one conditional CDF
//                    per row (row j at (H + 1) + j·(W + 1)); each 0 … 1.
struct GpuEnvironment {
  vec4 transform;  // x: cos(rotation), y: sin(rotation), z: scale, w: power ≈ ∫ Y(L) dω (scale included)
  uvec4 size;      // x: width W, y: height H, z: 1 if it can be sampled (else pdf 0), w: 0
};

// An emissive grid medium's emission CDF (144 bytes). Cells are the dual cells
// of the density texture: cell (i, j, k) spans cell coordinates [i, i+1) × … ,
// where cell coordinate c = index − origin, so texel i's centre is at c = i and
// a cell's 8 corners are the 8 texels its trilinear lookups blend.
// Buffers (names the includer declares, see lights.glsl):
//   emission_cdf[entry]:   inclusive CDF over the cells of weight > 0 (last = 1)
//   emission_cells[entry]: linear index x + X·(y + Y·z) of that cell (ascending)
//   emission_pmf[cell]:    probability of EVERY cell (0 for cells never chosen)
// Several media may share the buffers: entries [offsets.x, offsets.x + cells.w)
// and cells [offsets.y, offsets.y + X·Y·Z) belong to this medium.
struct GpuEmissionCdf {
  vec4 world_to_cell_row0;  // c = (dot(row0, p1), dot(row1, p1), dot(row2, p1)), p1 = (p, 1)
  vec4 world_to_cell_row1;
  vec4 world_to_cell_row2;
  vec4 cell_to_world_row0;  // p = (dot(row0, c1), dot(row1, c1), dot(row2, c1)), c1 = (c, 1)
  vec4 cell_to_world_row1;
  vec4 cell_to_world_row2;
  uvec4 cells;    // xyz: cells per axis (= density dims − 1); w: entry count (cells of weight > 0)
  uvec4 offsets;  // x: first entry in emission_cdf / emission_cells; y: first cell in emission_pmf; zw: 0
  vec4 measure;   // x: cell volume |det| (world units³); y: 1 / volume; z: power ∫ w dV;
                  // w: probability that next-event estimation picks this light (render.comp)
};

#ifdef __cplusplus
static_assert(sizeof(GpuEnvironment) == 32);
static_assert(offsetof(GpuEnvironment, size) == 16);
static_assert(sizeof(GpuEmissionCdf) == 144);
static_assert(offsetof(GpuEmissionCdf, cells) == 96);
static_assert(offsetof(GpuEmissionCdf, measure) == 128);
}  // namespace pyrolume::gpu
#endif
#endif
