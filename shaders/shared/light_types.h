// Light-sampling structs shared by the host (C++) and the shaders (GLSL): the
// environment map and the emission CDF of an emissive grid medium
// (docs/lights.md; host/light/EnvironmentMap, host/light/EmissionCdf;
// shaders/lights.glsl). Same rules as gpu_types.h: written in the common subset
// of both languages, vec4/uvec4 members or a vec3 and a 4-byte scalar per
// 16 bytes (std140, std430 and C++ agree), every size and offset
// static_asserted. Binding numbers are the includer's (render.comp's
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
  float cos_rotation, sin_rotation;
  float scale;      // radiance = texel rgb × scale
  float power;      // ≈ ∫ Y(L) dω (scale included)
  uint width, height;
  uint can_sample;  // 1 if it can be sampled (else pdf 0)
  uint zenith_y;    // 1 if the zenith is world +Y (else +Z)
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
// Several media may share the buffers: entries [first_entry, first_entry + entry_count),
// cells [first_cell, first_cell + X·Y·Z) and clusters [first_cluster, first_cluster + CX·CY·CZ)
// belong to this medium.
struct GpuEmissionCdf {
  vec4 world_to_cell_row0;  // c = (dot(row0, p1), dot(row1, p1), dot(row2, p1)), p1 = (p, 1)
  vec4 world_to_cell_row1;
  vec4 world_to_cell_row2;
  vec4 cell_to_world_row0;  // p = (dot(row0, c1), dot(row1, c1), dot(row2, c1)), c1 = (c, 1)
  vec4 cell_to_world_row1;
  vec4 cell_to_world_row2;
  uvec3 cells;           // cells per axis (= density dims − 1)
  uint entry_count;      // cells of weight > 0
  uint first_entry;      // in emission_cdf / emission_cells
  uint first_cell;       // in emission_pmf
  // In emission_clusters: the grid of clusters, then copies of the nonempty
  // ones, which the loops over clusters read.
  uint first_cluster;
  uint nonempty_clusters;
  uvec3 clusters;        // clusters per axis
  uint cluster_k;        // cells per cluster per axis
  float cell_volume;     // |det| (world units³)
  float inv_cell_volume;
  float power;           // ∫ w dV
  float pick_probability;  // that next-event estimation picks this light
};

// One cluster of an emission CDF (48 bytes).
struct GpuEmissionCluster {
  vec3 center;       // world-space centre of the bounding sphere of its cells of weight > 0
  float radius_sq;   // that sphere's radius²
  float power;       // its share of the emission (0: empty)
  uint unused0, unused1, unused2;
  uint first_entry;  // relative to GpuEmissionCdf first_entry
  uint entry_count;
  uint unused3, unused4;
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
  vec3 position;   // point or spot position, sphere centre
  float radius;    // sphere
  vec3 direction;  // unit: distant, disc: toward the light; spot: where it shines
  float unused0;
  vec3 value;      // intensity (point, spot; W/sr), irradiance (distant), radiance (disc, sphere)
  float pick_probability;  // that next-event estimation picks this light
  float cos_cone;          // spot: cos of the cone's half-angle
  float cos_falloff;       // spot: cos of where the falloff starts
  float one_minus_cos;     // disc: 1 − cos θ (θ its angular radius)
  float sin2;              // disc: sin²θ
  uint kind;               // LIGHT_*
  uint unused1, unused2, unused3;
};

#ifdef __cplusplus
static_assert(sizeof(GpuEnvironment) == 32);
PYRO_OFFSET(GpuEnvironment, sin_rotation, 4); PYRO_OFFSET(GpuEnvironment, scale, 8);
PYRO_OFFSET(GpuEnvironment, power, 12);
PYRO_OFFSET(GpuEnvironment, width, 16); PYRO_OFFSET(GpuEnvironment, height, 20);
PYRO_OFFSET(GpuEnvironment, can_sample, 24); PYRO_OFFSET(GpuEnvironment, zenith_y, 28);
static_assert(sizeof(GpuEmissionCdf) == 160);
PYRO_OFFSET(GpuEmissionCdf, world_to_cell_row1, 16); PYRO_OFFSET(GpuEmissionCdf, world_to_cell_row2, 32);
PYRO_OFFSET(GpuEmissionCdf, cell_to_world_row0, 48); PYRO_OFFSET(GpuEmissionCdf, cell_to_world_row1, 64);
PYRO_OFFSET(GpuEmissionCdf, cell_to_world_row2, 80); PYRO_OFFSET(GpuEmissionCdf, cells, 96);
PYRO_OFFSET(GpuEmissionCdf, entry_count, 108); PYRO_OFFSET(GpuEmissionCdf, first_entry, 112);
PYRO_OFFSET(GpuEmissionCdf, first_cell, 116); PYRO_OFFSET(GpuEmissionCdf, first_cluster, 120);
PYRO_OFFSET(GpuEmissionCdf, nonempty_clusters, 124); PYRO_OFFSET(GpuEmissionCdf, clusters, 128);
PYRO_OFFSET(GpuEmissionCdf, cluster_k, 140); PYRO_OFFSET(GpuEmissionCdf, cell_volume, 144);
PYRO_OFFSET(GpuEmissionCdf, inv_cell_volume, 148); PYRO_OFFSET(GpuEmissionCdf, power, 152);
PYRO_OFFSET(GpuEmissionCdf, pick_probability, 156);
static_assert(sizeof(GpuEmissionCluster) == 48);
PYRO_OFFSET(GpuEmissionCluster, radius_sq, 12); PYRO_OFFSET(GpuEmissionCluster, power, 16);
PYRO_OFFSET(GpuEmissionCluster, unused0, 20); PYRO_OFFSET(GpuEmissionCluster, unused1, 24);
PYRO_OFFSET(GpuEmissionCluster, unused2, 28); PYRO_OFFSET(GpuEmissionCluster, first_entry, 32);
PYRO_OFFSET(GpuEmissionCluster, entry_count, 36); PYRO_OFFSET(GpuEmissionCluster, unused3, 40);
PYRO_OFFSET(GpuEmissionCluster, unused4, 44);
static_assert(sizeof(GpuLight) == 80);
PYRO_OFFSET(GpuLight, radius, 12); PYRO_OFFSET(GpuLight, direction, 16); PYRO_OFFSET(GpuLight, unused0, 28);
PYRO_OFFSET(GpuLight, value, 32); PYRO_OFFSET(GpuLight, pick_probability, 44); PYRO_OFFSET(GpuLight, cos_cone, 48);
PYRO_OFFSET(GpuLight, cos_falloff, 52); PYRO_OFFSET(GpuLight, one_minus_cos, 56); PYRO_OFFSET(GpuLight, sin2, 60);
PYRO_OFFSET(GpuLight, kind, 64); PYRO_OFFSET(GpuLight, unused1, 68); PYRO_OFFSET(GpuLight, unused2, 72);
PYRO_OFFSET(GpuLight, unused3, 76);
}  // namespace pyrolume::gpu
#endif
#endif
