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
// v = 0 the top row. World direction d is looked up at Rz(−rotation)·d, or
// in a Y-up scene at Rz(−rotation)·(d.x, −d.z, d.y) (the zenith on world +Y).
// Buffers (names the includer declares, see lights.glsl):
//   env_texels[W·H]: vec4(r, g, b, p_uv), row 0 = top; p_uv = the piecewise-constant
//                    (u, v) sampling density of that texel; radiance = rgb × scale.
//   env_cdf[(H + 1) + H·(W + 1)]: marginal CDF over rows, then one conditional CDF
//                    per row (row j at (H + 1) + j·(W + 1)); each 0 … 1.
struct GpuEnvironment {
  vec4 transform;  // x: cos(rotation), y: sin(rotation), z: scale, w: power ≈ ∫ Y(L) dω (scale included)
  uvec4 size;      // x: width W, y: height H, z: 1 if it can be sampled (else pdf 0), w: 1 if the zenith is world +Y (else +Z)
};

// An emissive grid medium's emission CDF as seen from a receiver (160 bytes;
// host/light/EmissionCdf clustered()). Cells are the dual cells of the
// density texture: cell (i, j, k) spans cell coordinates [i, i+1) × … , where
// cell coordinate c = index − origin, so texel i's centre is at c = i and a
// cell's 8 corners are the 8 texels its trilinear lookups blend. Clusters of
// k³ cells: from receiver o, cluster s is chosen with probability
// I_s(o) / Σ I, I_s(o) = power_s / max(|o − centre_s|², radius_s²), then a
// cell by its probability within the cluster.
// Buffers (names the includer declares, see lights.glsl):
//   emission_cdf[entry]:      inclusive CDF within the entry's cluster (last of each = 1)
//   emission_cells[entry]:    linear index x + X·(y + Y·z) of that cell (grouped by cluster)
//   emission_pmf[cell]:       probability of EVERY cell within its cluster (0: never chosen)
//   emission_clusters[s]:     GpuEmissionCluster, linear over the cluster grid like cells
// Several media may share the buffers: entries [offsets.x, offsets.x + cells.w),
// cells [offsets.y, offsets.y + X·Y·Z) and clusters [offsets.z, offsets.z + CX·CY·CZ)
// belong to this medium.
struct GpuEmissionCdf {
  vec4 world_to_cell_row0;  // c = (dot(row0, p1), dot(row1, p1), dot(row2, p1)), p1 = (p, 1)
  vec4 world_to_cell_row1;
  vec4 world_to_cell_row2;
  vec4 cell_to_world_row0;  // p = (dot(row0, c1), dot(row1, c1), dot(row2, c1)), c1 = (c, 1)
  vec4 cell_to_world_row1;
  vec4 cell_to_world_row2;
  uvec4 cells;    // xyz: cells per axis (= density dims − 1); w: entry count (cells of weight > 0)
  uvec4 offsets;  // x: first entry in emission_cdf / emission_cells; y: first cell in emission_pmf;
                  // z: first cluster in emission_clusters (the grid of clusters, then copies
                  // of the nonempty ones, which the loops over clusters read); w: their count
  uvec4 clusters; // xyz: clusters per axis; w: k, cells per cluster per axis
  vec4 measure;   // x: cell volume |det| (world units³); y: 1 / volume; z: power ∫ w dV;
                  // w: probability that next-event estimation picks this light (render.comp)
};

// One cluster of an emission CDF (48 bytes).
struct GpuEmissionCluster {
  vec4 sphere;     // xyz: world-space centre of the bounding sphere of its cells of weight > 0; w: radius²
  vec4 power;      // x: its share of the emission (0: empty); yzw: 0
  uvec4 entries;   // x: its first entry (relative to offsets.x); y: its entry count; zw: 0
};

// The kinds of analytic light (the scene's `lights`; docs/lights.md
// "Analytic lights"). The first three are delta lights.
PYRO_CONST uint LIGHT_POINT = 0;
PYRO_CONST uint LIGHT_SPOT = 1;
PYRO_CONST uint LIGHT_DISTANT = 2;  // a delta distant light (angle_deg 0)
PYRO_CONST uint LIGHT_DISC = 3;     // a distant light of angular diameter > 0
PYRO_CONST uint LIGHT_SPHERE = 4;

// One analytic light (80 bytes; buffer analytic_lights[], shaders/analytic_lights.glsl).
struct GpuLight {
  vec4 position;   // xyz: point or spot position, sphere centre; w: sphere radius
  vec4 direction;  // xyz unit: distant, disc: toward the light; spot: where it shines; w: 0
  vec4 value;      // rgb: intensity (point, spot; W/sr), irradiance (distant), radiance (disc, sphere);
                   // w: probability that next-event estimation picks this light
  vec4 cone;       // spot: x cos of the cone's half-angle, y cos of where the falloff starts;
                   // disc: z 1 − cos θ, w sin²θ (θ its angular radius); else 0
  uvec4 kind;      // x: LIGHT_*; yzw: 0
};

#ifdef __cplusplus
static_assert(sizeof(GpuLight) == 80);
static_assert(offsetof(GpuLight, cone) == 48);
static_assert(offsetof(GpuLight, kind) == 64);
static_assert(sizeof(GpuEmissionCluster) == 48);
static_assert(sizeof(GpuEnvironment) == 32);
static_assert(offsetof(GpuEnvironment, size) == 16);
static_assert(sizeof(GpuEmissionCdf) == 160);
static_assert(offsetof(GpuEmissionCdf, cells) == 96);
static_assert(offsetof(GpuEmissionCdf, measure) == 144);
}  // namespace pyrolume::gpu
#endif
#endif
