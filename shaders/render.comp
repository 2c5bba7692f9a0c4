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

// Specialisation: a scene without grids/scattering/emission compiles none of that code.
layout(constant_id = SPEC_HAS_GRIDS) const bool HAS_GRIDS = true;
layout(constant_id = SPEC_HAS_ANALYTIC_MEDIA) const bool HAS_ANALYTIC_MEDIA = true;
layout(constant_id = SPEC_HAS_SCATTERING) const bool HAS_SCATTERING = true;
layout(constant_id = SPEC_HAS_EMISSION) const bool HAS_EMISSION = true;
layout(constant_id = SPEC_COLLISION_ESTIMATOR) const bool COLLISION_ESTIMATOR = false;
layout(constant_id = SPEC_DEBUG_MODE) const uint DEBUG_MODE = DEBUG_NONE;
// A constant trip count lets the compiler unroll the per-medium loops and keep
// span[], rho[] and temperature_value[] in registers instead of per-lane scratch memory (lavapipe).
layout(constant_id = SPEC_MEDIUM_COUNT) const uint MEDIUM_COUNT = 1;
const uint MEDIA_N = MEDIUM_COUNT > 0u ? MEDIUM_COUNT : 1u;  // array size (never 0)
// With a single grid medium the texture switches below fold to slot 0 (15 %
// faster on lavapipe than a switch the compiler cannot resolve).
layout(constant_id = SPEC_GRID_COUNT) const uint GRID_COUNT = 1;
layout(constant_id = SPEC_HAS_SURFACES) const bool HAS_SURFACES = false;
layout(constant_id = SPEC_SURFACE_SHAPE_COUNT) const uint SURFACE_SHAPE_COUNT = 0;
layout(constant_id = SPEC_SURFACE_HAS_TRIANGLES) const bool SURFACE_HAS_TRIANGLES = false;
layout(constant_id = SPEC_ALBEDO_TEXTURE_COUNT) const uint ALBEDO_TEXTURE_COUNT = MAX_TEXTURES;
layout(constant_id = SPEC_HAS_ENVIRONMENT) const bool HAS_ENVIRONMENT = false;
layout(constant_id = SPEC_LIGHT_STRATEGY) const uint LIGHT_STRATEGY = LIGHT_STRATEGY_BSDF;
const bool NEE = LIGHT_STRATEGY != LIGHT_STRATEGY_BSDF;  // next-event estimation (with the collision estimator)
// Continuations drawn from the lights with probability 1 − frame.lights.y; off
// (frame.lights.y = 1) compiles that code out: llvmpipe runs every branch.
layout(constant_id = SPEC_GUIDED_CONTINUATION) const bool GUIDED_CONTINUATION = false;
// The free-flight loop in path_track leaves once half of the SIMD group's lanes
// have found their event, instead of waiting for the last one (the device
// supports subgroup ballots; the host sets it where it pays, docs/benchmarks.md).
layout(constant_id = SPEC_EARLY_EVENT_EXIT) const bool EARLY_EVENT_EXIT = false;
// The temperature is the density texture's second channel: the density lookup
// at a collision reads it too, and the emission there needs no lookup of its own
// (docs/rendering.md "One texture for density and temperature").
layout(constant_id = SPEC_TEMPERATURE_IN_DENSITY) const bool TEMPERATURE_IN_DENSITY = false;
// The scene's analytic lights (shaders/analytic_lights.glsl); 0: none of their code.
layout(constant_id = SPEC_LIGHT_COUNT) const uint LIGHT_COUNT = 0;

layout(std140, set = 0, binding = BINDING_FRAME) uniform FrameBlock { FrameConstants frame; };
// Media and grids are uniform blocks: every lane reads the same entries, which
// uniform loads serve without per-lane gathers.
layout(std140, set = 0, binding = BINDING_MEDIA) uniform MediaBlock { GpuMedium media[MAX_MEDIA]; };
layout(std430, set = 0, binding = BINDING_ACCUM) buffer AccumBlock { AccumTexel accum[]; };
layout(std140, set = 0, binding = BINDING_GRIDS) uniform GridBlock { GpuGrid grids[MAX_GRIDS]; };
layout(std430, set = 0, binding = BINDING_MAJORANTS) readonly buffer MajorantBlock { float majorants[]; };
layout(set = 0, binding = BINDING_DENSITY) uniform sampler3D density_tex[MAX_GRIDS];
layout(set = 0, binding = BINDING_TEMPERATURE) uniform sampler3D temperature_tex[MAX_GRIDS];
layout(set = 0, binding = BINDING_BLACKBODY) uniform sampler1D blackbody_tex[MAX_GRIDS];
layout(push_constant) uniform PassBlock { PassConstants pass_constants; };
layout(std430, set = 0, binding = BINDING_PASS_STATUS) buffer PassStatusBlock { PassStatus pass_status; };
// Surfaces (shaders/bvh.glsl's contract).
layout(std430, set = 0, binding = BINDING_BVH_NODES) readonly buffer BvhNodes { GpuBvhNode bvh_nodes[]; };
layout(std430, set = 0, binding = BINDING_BVH_TRIANGLES) readonly buffer BvhTriangles { GpuTriangle bvh_triangles[]; };
layout(std430, set = 0, binding = BINDING_BVH_ATTRIBUTES) readonly buffer BvhAttributes {
  GpuTriangleAttributes bvh_attributes[];
};
layout(std430, set = 0, binding = BINDING_SURFACE_SHAPES) readonly buffer SurfaceShapes {
  GpuSurfaceShape surface_shapes[];
};
layout(std430, set = 0, binding = BINDING_MATERIALS) readonly buffer Materials { GpuMaterial surface_materials[]; };
layout(set = 0, binding = BINDING_TEXTURES) uniform sampler2D albedo_tex[MAX_TEXTURES];
#include "bvh.glsl"
// The environment map (shaders/lights.glsl's contract).
#include "shared/light_types.h"
#define LIGHTS_ENVIRONMENT
layout(std430, set = 0, binding = BINDING_ENV_TEXELS) readonly buffer EnvTexelBlock { vec4 env_texels[]; };
layout(std430, set = 0, binding = BINDING_ENV_CDF) readonly buffer EnvCdfBlock { float env_cdf[]; };
layout(std140, set = 0, binding = BINDING_ENV_HEADER) uniform EnvHeaderBlock { GpuEnvironment environment; };
#define LIGHTS_EMISSION
layout(std430, set = 0, binding = BINDING_EMISSION_CDF) readonly buffer EmissionCdfBlock { float emission_cdf[]; };
layout(std430, set = 0, binding = BINDING_EMISSION_CELLS) readonly buffer EmissionCellBlock { uint emission_cells[]; };
layout(std430, set = 0, binding = BINDING_EMISSION_PMF) readonly buffer EmissionPmfBlock { float emission_pmf[]; };
layout(std430, set = 0, binding = BINDING_EMISSION_CLUSTERS) readonly buffer EmissionClusterBlock {
  GpuEmissionCluster emission_clusters[];
};
layout(std140, set = 0, binding = BINDING_EMISSION_HEADERS) uniform EmissionHeaderBlock {
  GpuEmissionCdf emission_lights[MAX_GRIDS];  // by grid slot; measure.w: probability of picking it
};
#include "lights.glsl"
layout(std430, set = 0, binding = BINDING_LIGHTS) readonly buffer AnalyticLightBlock { GpuLight analytic_lights[]; };
#include "analytic_lights.glsl"
// What a ray hits: a sphere light, or where a delta light ray meets its light.
const uint SURFACE_HIT_LIGHT = 2u;

const float INF = 1.0 / 0.0;

float avg3(vec3 v) { return (v.x + v.y + v.z) * (1.0 / 3.0); }
float max3(vec3 v) { return max(v.x, max(v.y, v.z)); }
float min3(vec3 v) { return min(v.x, min(v.y, v.z)); }

// Whether medium m is a grid (else a sphere or a box). Without analytic media
// the test and the analytic code compile out: llvmpipe runs both sides of
// every branch, and that code cost ~5 % of a grid scene's time.
bool is_grid(GpuMedium m) { return HAS_GRIDS && (!HAS_ANALYTIC_MEDIA || uint(m.sigma_a.w) == SHAPE_GRID); }

struct PathStats {
  float events;   // real collisions: absorptions + scatterings
  float lookups;  // density texture lookups
};

// Texture arrays are indexed with constants only (no dependence on
// dynamically-uniform indexing, which lavapipe and older GPUs handle poorly).
// With TEMPERATURE_IN_DENSITY, .y is the temperature grid's value (else 0).
vec2 density_at(uint slot, vec3 tc) {
  if (GRID_COUNT <= 1u) slot = 0u;
  vec2 v;
  switch (slot) {
    case 0u: v = textureLod(density_tex[0], tc, 0.0).rg; break;
    case 1u: v = textureLod(density_tex[1], tc, 0.0).rg; break;
    case 2u: v = textureLod(density_tex[2], tc, 0.0).rg; break;
    default: v = textureLod(density_tex[3], tc, 0.0).rg; break;
  }
  return TEMPERATURE_IN_DENSITY ? v : vec2(v.x, 0.0);
}
float temperature_at(uint slot, vec3 tc) {
  if (GRID_COUNT <= 1u) slot = 0u;
  switch (slot) {
    case 0u: return textureLod(temperature_tex[0], tc, 0.0).r;
    case 1u: return textureLod(temperature_tex[1], tc, 0.0).r;
    case 2u: return textureLod(temperature_tex[2], tc, 0.0).r;
    default: return textureLod(temperature_tex[3], tc, 0.0).r;
  }
}
vec3 blackbody_at(uint slot, float s) {
  if (GRID_COUNT <= 1u) slot = 0u;
  switch (slot) {
    case 0u: return textureLod(blackbody_tex[0], s, 0.0).rgb;
    case 1u: return textureLod(blackbody_tex[1], s, 0.0).rgb;
    case 2u: return textureLod(blackbody_tex[2], s, 0.0).rgb;
    default: return textureLod(blackbody_tex[3], s, 0.0).rgb;
  }
}

// Grid fields are read straight from the uniform block (no GpuGrid copies:
// copying the 192-byte struct per call is measurably slower on lavapipe).
// With at most one texture the slot is 0 and the switch's other cases
// compile out: each is a texture lookup, which llvmpipe runs for the whole
// SIMD group whether or not a lane takes it.
vec3 albedo_texture_at(uint slot, vec2 uv) {
  if (ALBEDO_TEXTURE_COUNT <= 1u) return textureLod(albedo_tex[0], uv, 0.0).rgb;
  switch (slot) {
    case 0u: return textureLod(albedo_tex[0], uv, 0.0).rgb;
    case 1u: return textureLod(albedo_tex[1], uv, 0.0).rgb;
    case 2u: return textureLod(albedo_tex[2], uv, 0.0).rgb;
    case 3u: return textureLod(albedo_tex[3], uv, 0.0).rgb;
    case 4u: return textureLod(albedo_tex[4], uv, 0.0).rgb;
    case 5u: return textureLod(albedo_tex[5], uv, 0.0).rgb;
    case 6u: return textureLod(albedo_tex[6], uv, 0.0).rgb;
    default: return textureLod(albedo_tex[7], uv, 0.0).rgb;
  }
}

vec3 density_texel(uint slot, vec3 p) {
  vec4 p1 = vec4(p, 1.0);
  return vec3(dot(grids[slot].density_row0, p1), dot(grids[slot].density_row1, p1), dot(grids[slot].density_row2, p1));
}
vec3 density_texel_dir(uint slot, vec3 d) {
  vec4 d0 = vec4(d, 0.0);
  return vec3(dot(grids[slot].density_row0, d0), dot(grids[slot].density_row1, d0), dot(grids[slot].density_row2, d0));
}

// Emitted radiance Le of grid medium m at world point x (docs/scene-format.md "media": T = (v − offset)·scale,
// no emission at or below cutoff_k; the LUT is uniform in ln T). With
// TEMPERATURE_IN_DENSITY the grid's value v was read with the density at x.
vec3 grid_le(GpuMedium m, uint slot, vec3 x, float value_read) {
  uint mode = uint(m.emission.w);
  if (mode == EMIT_CONSTANT) return m.emission.rgb;
  if (mode != EMIT_TEMPERATURE) return vec3(0.0);
  float value = value_read;
  if (!TEMPERATURE_IN_DENSITY) {
    vec4 p1 = vec4(x, 1.0);
    vec3 u = vec3(dot(grids[slot].temperature_row0, p1), dot(grids[slot].temperature_row1, p1),
                  dot(grids[slot].temperature_row2, p1));
    value = temperature_at(slot, u / grids[slot].temperature_dims.xyz);
  }
  vec4 map = grids[slot].temperature_map, lut = grids[slot].blackbody_lut;
  float T = (value - map.x) * map.y;
  if (!(T > map.z) || !(T >= lut.z)) return vec3(0.0);
  return m.emission.rgb * blackbody_at(slot, log(T) * lut.x + lut.y);
}

// The media's extent along a ray: [t_enter, t_exit], (-1,-1) when missed.
void media_spans(vec3 o, vec3 d, out vec2 span[MEDIA_N], out bool any_hit) {
  any_hit = false;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    GpuMedium m = media[i];
    uint shape = uint(m.sigma_a.w);
    vec2 t;
    bool hit;
    if (is_grid(m)) {
      // The texel box [0, dims] in texel space; t is the same there (affine map).
      uint slot = uint(m.bounds0.x);
      // Clip to the trilinear support, between the zero padding texels' centres
      // (u = 0.5 .. dims − 0.5): outside it every lookup is 0, and a dense grid's
      // majorant there would only buy null collisions.
      hit = intersect_box(density_texel(slot, o), density_texel_dir(slot, d), vec3(0.5),
                          grids[slot].density_dims.xyz - 0.5, t);
    } else if (shape == SHAPE_SPHERE) {
      hit = intersect_sphere(o, d, m.bounds0.xyz, m.bounds0.w, t);
    } else {
      hit = intersect_box(o, d, m.bounds0.xyz, m.bounds1.xyz, t);
    }
    span[i] = hit ? t : vec2(-1.0);
    any_hit = any_hit || hit;
  }
}

// Majorant of grid medium m over the DDA cell the ray is in at t, and the t at
// which the ray leaves that cell. Stateless: the cell is found at t + a small
// nudge along the ray, so a point on a face belongs to the cell being entered.
float grid_majorant(GpuMedium m, vec3 o, vec3 d, float t, float t_span_end, inout float t_next) {
  uint slot = uint(m.bounds0.x);
  vec3 u = density_texel(slot, o + t * d);
  vec3 du = density_texel_dir(slot, d);
  vec4 cell_info = grids[slot].majorant_cell;
  uvec4 res4 = grids[slot].majorant_res;
  vec3 cs = cell_info.xyz;
  vec3 inv_du = 1.0 / du;
  float nudge = 1e-4 * min3(cs) / max(max3(abs(du)), 1e-30);
  // At least a few float ulps of t, so t always moves on (a far camera loses
  // precision in u; see also the origin shift in path_begin).
  float min_step = max(nudge, abs(t) * 1e-6);
  ivec3 res = ivec3(res4.xyz);
  ivec3 cell = clamp(ivec3(floor((u + du * nudge) / cs)), ivec3(0), res - 1);
  vec3 bound = (vec3(cell) + step(vec3(0.0), du)) * cs;
  vec3 tx = (bound - u) * inv_du;  // ±inf on axes the ray runs parallel to
  vec3 t_axis = t + mix(tx, vec3(INF), isnan(tx));  // where the ray crosses each axis' next face
  uint index = res4.w + uint((cell.z * res.y + cell.y) * res.x + cell.x);
  float majorant = majorants[index];
  if (majorant > 0.0) {
    t_next = min(t_next, max(min3(t_axis), t + min_step));
    return majorant * cell_info.w;
  }
  // An empty cell: walk the DDA on to the first non-empty cell (or out of the
  // grid) right here, so a run of empty cells costs one tracking step.
  vec3 t_delta = abs(cs * inv_du);
  ivec3 dir = ivec3(sign(du));
  float t_enter = min3(t_axis);
  for (uint n = 0u; n < 256u && t_enter < t_span_end; ++n) {
    int a = t_axis.x <= t_axis.y ? (t_axis.x <= t_axis.z ? 0 : 2) : (t_axis.y <= t_axis.z ? 1 : 2);
    cell[a] += dir[a];
    if (cell[a] < 0 || cell[a] >= res[a]) {
      t_enter = INF;  // left the grid: empty up to the span's end
      break;
    }
    t_axis[a] += t_delta[a];
    index = res4.w + uint((cell.z * res.y + cell.y) * res.x + cell.x);
    if (majorants[index] > 0.0) break;
    t_enter = min3(t_axis);
  }
  t_next = min(t_next, max(t_enter, t + min_step));
  return 0.0;
}

// Media coefficients at a tentative collision; rho[i] keeps each grid's
// density_scale · density for the scattering-lobe choice, and
// temperature_value[i] its temperature grid's value where the density lookup
// reads it (TEMPERATURE_IN_DENSITY; else 0).
void coefficients_at(vec3 x, float t, vec2 span[MEDIA_N], out vec3 sigma_a, out vec3 sigma_s, out float rho[MEDIA_N],
                     out float temperature_value[MEDIA_N], inout PathStats stats) {
  sigma_a = vec3(0.0);
  sigma_s = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    rho[i] = 0.0;
    temperature_value[i] = 0.0;
    if (!(span[i].x <= t && t < span[i].y)) continue;
    GpuMedium m = media[i];
    float r = 1.0;
    if (is_grid(m)) {
      uint slot = uint(m.bounds0.x);
      vec4 dims = grids[slot].density_dims;
      const vec2 v = density_at(slot, density_texel(slot, x) / dims.xyz);
      r = dims.w * v.x;
      temperature_value[i] = v.y;
      stats.lookups += 1.0;
    }
    rho[i] = r;
    sigma_a += r * m.sigma_a.rgb;
    sigma_s += r * m.sigma_s.rgb;
  }
}

// MIS weight of the radiance that phase/BSDF sampling finds along its ray
// before the next real event (emission at tentative collisions, the
// environment on escape), against next-event estimation's solid-angle pdf
// p_light for the same direction (docs/mis.md): the power heuristic (Veach
// 1997 eq. 9.13) as 1/(1 + r²), which cannot overflow. pdf_dir = 0 marks a
// camera or light ray: weight 1.
float unidirectional_weight(float pdf_dir, float p_light) {
  if (!NEE || !(pdf_dir > 0.0) || !(p_light > 0.0)) return 1.0;
  if (LIGHT_STRATEGY == LIGHT_STRATEGY_LIGHT_ONLY) return 0.0;
  float r = p_light / pdf_dir;
  return 1.0 / (1.0 + r * r);
}
float light_weight(float p_light, float pdf_dir) {
  if (LIGHT_STRATEGY == LIGHT_STRATEGY_LIGHT_ONLY) return 1.0;
  float r = pdf_dir / p_light;
  return 1.0 / (1.0 + r * r);
}

// Emitted power per unit length, Σ sigma_a_i(x)·Le_i(x), over the media at t.
vec3 emission_at(vec3 x, float t, vec2 span[MEDIA_N], float rho[MEDIA_N], float temperature_value[MEDIA_N]) {
  vec3 E = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].x <= t && t < span[i].y)) continue;
    GpuMedium m = media[i];
    if (is_grid(m)) {
      if (rho[i] > 0.0) E += rho[i] * m.sigma_a.rgb * grid_le(m, uint(m.bounds0.x), x, temperature_value[i]);
    } else {
      E += m.emission.rgb;
    }
  }
  return E;
}

// Local majorant over [t, t_next): sum over the media present of their bound.
float majorant_at(vec3 o, vec3 d, float t, vec2 span[MEDIA_N], out float t_next, out bool any_ahead) {
  float sigma_bar = 0.0;
  t_next = INF;
  any_ahead = false;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    vec2 s = span[i];
    if (s.y <= t) continue;
    any_ahead = true;
    if (s.x > t) {
      t_next = min(t_next, s.x);
      continue;
    }
    t_next = min(t_next, s.y);
    GpuMedium m = media[i];
    if (is_grid(m)) sigma_bar += grid_majorant(m, o, d, t, s.y, t_next);
    else sigma_bar += max3(m.sigma_a.rgb + m.sigma_s.rgb);
  }
  return sigma_bar;
}

// Below this running transmittance estimate, ratio tracking plays Russian
// roulette (transmittance() and light rays).
const float RATIO_TRACKING_ROULETTE_BELOW = 0.1;
// Once scatterings that next-event estimation keeps from being absorbed have
// lowered a path's weight below this fraction, Russian roulette (path_step).
const float SCATTER_ROULETTE_BELOW = 0.1;

// Transmittance along a ray to infinity, per channel. Ratio tracking (Novák et
// al. 2014): multiply by the null fraction sigma_n/sigma_bar at every tentative
// collision, with Russian roulette once the estimate is small. Delta tracking
// (spectral: Kutz et al. 2017) terminates at real collisions instead.
vec3 transmittance(vec3 o, vec3 d, bool ratio, inout uint rng, inout PathStats stats) {
  vec2 span[MEDIA_N];
  bool any_hit;
  media_spans(o, d, span, any_hit);
  vec3 T = vec3(1.0);
  float t = 0.0;
  for (;;) {
    float t_next;
    bool any_ahead;
    float sigma_bar = majorant_at(o, d, t, span, t_next, any_ahead);
    if (!any_ahead || isinf(t_next)) return T;
    if (sigma_bar <= 0.0) { t = t_next; continue; }
    float dt = sample_free_flight(sigma_bar, rng_next(rng));
    if (t + dt >= t_next) { t = t_next; continue; }
    t += dt;
    vec3 sigma_a, sigma_s;
    float rho[MEDIA_N], temperature_value[MEDIA_N];
    coefficients_at(o + t * d, t, span, sigma_a, sigma_s, rho, temperature_value, stats);
    vec3 sigma_n = max(vec3(sigma_bar) - sigma_a - sigma_s, vec3(0.0));
    if (ratio) {
      T *= sigma_n / sigma_bar;
      float q = max3(T);
      if (q < RATIO_TRACKING_ROULETTE_BELOW) {  // Russian roulette: survive with probability q, reweight by 1/q
        if (rng_next(rng) >= q) return vec3(0.0);
        T /= q;
      }
    } else {
      float p_null = avg3(sigma_n * T) / (sigma_bar * avg3(T));
      if (rng_next(rng) >= p_null) return vec3(0.0);
      T *= sigma_n / (sigma_bar * p_null);
    }
  }
  return T;
}

// The normalisers of the emissive grids' light distributions seen from
// vertex o (emission_receiver_norm), by grid slot: computed once per vertex.
void light_norms(vec3 o, out vec4 norm) {
  norm = vec4(0.0);
  if (HAS_GRIDS && HAS_EMISSION)
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      if (!is_grid(media[i])) continue;
      const uint slot = uint(media[i].bounds0.x);
      if (emission_lights[slot].measure.w > 0.0) norm[slot] = emission_receiver_norm(emission_lights[slot], o);
    }
}

// The solid-angle pdf with which next-event estimation at o picks direction
// d (docs/mis.md): the environment map's, and each emissive grid's pdf of the
// direction toward a point of its emission CDF seen from o, mixed by the
// light choice. norm: light_norms(o).
float light_direction_pdf(vec3 o, vec4 norm, vec3 d) {
  float p = 0.0;
  if (HAS_ENVIRONMENT && frame.lights.x > 0.0) p += frame.lights.x * env_pdf(environment, d);
  if (HAS_GRIDS && HAS_EMISSION)
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      if (!is_grid(media[i])) continue;
      GpuEmissionCdf e = emission_lights[uint(media[i].bounds0.x)];
      if (e.measure.w > 0.0) p += e.measure.w * emission_direction_pdf(e, o, norm[uint(media[i].bounds0.x)], d);
    }
  for (uint i = 0u; i < LIGHT_COUNT; ++i)
    if (analytic_lights[i].value.w > 0.0) p += analytic_lights[i].value.w * analytic_light_pdf(analytic_lights[i], o, d);
  return p;
}

// A light direction for next-event estimation from point o: the environment
// map's, toward a point drawn from an emissive grid's emission CDF, or toward
// an analytic light (the light chosen by frame.lights.x, each grid's
// measure.w and each analytic light's value.w). false: none. A delta light
// sets delta_light to its index and delta_w to what it delivers along dir per
// unit of f, over its probability; otherwise delta_light = LIGHT_COUNT.
bool sample_light_direction(vec3 o, vec4 norm, inout uint rng, out vec3 dir, out vec3 delta_w, out uint delta_light) {
  dir = vec3(0.0, 0.0, 1.0);
  delta_w = vec3(0.0);
  delta_light = LIGHT_COUNT;
  float u = rng_next(rng);
  vec2 u2 = vec2(rng_next(rng), rng_next(rng));
  float u_z = rng_next(rng);
  if (HAS_ENVIRONMENT && u < frame.lights.x) {
    EnvSample es = env_sample(environment, u2);
    dir = es.dir;
    return es.pdf > 0.0;
  }
  u -= frame.lights.x;
  // The grid medium whose light probability covers u.
  // (The last light when rounding leaves u past them all, like the CPU reference.)
  uint pick = MEDIUM_COUNT;
  bool found = false;
  if (HAS_GRIDS && HAS_EMISSION)
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      if (!is_grid(media[i])) continue;
      float p = emission_lights[uint(media[i].bounds0.x)].measure.w;
      if (!(p > 0.0) || found) continue;
      pick = i;
      if (u < p) found = true; else u -= p;
    }
  if (LIGHT_COUNT > 0u && !found) {
    // Past the grids: the analytic light whose probability covers u (the last one when rounding leaves u past them).
    uint light = LIGHT_COUNT;
    for (uint i = 0u; i < LIGHT_COUNT; ++i) {
      const float p = analytic_lights[i].value.w;
      if (!(p > 0.0) || found) continue;
      light = i;
      if (u < p) found = true; else u -= p;
    }
    if (light < LIGHT_COUNT) {
      const GpuLight l = analytic_lights[light];
      vec3 delta_value;
      if (!analytic_light_sample(l, o, u2, dir, delta_value)) return false;
      if (light_is_delta(l.kind.x)) {
        delta_light = light;
        delta_w = delta_value / l.value.w;
      }
      return true;
    }
  }
  if (!HAS_GRIDS || !HAS_EMISSION || pick == MEDIUM_COUNT) return false;
  const uint slot = uint(media[pick].bounds0.x);
  const float u_cluster = rng_next(rng), u_cell = rng_next(rng);
  EmissionSample es = emission_sample(emission_lights[slot], o, norm[slot], u_cluster, u_cell, vec3(u2, u_z));
  if (!(es.pdf > 0.0)) return false;
  vec3 v = es.p - o;
  float dist = length(v);
  if (!(dist > 0.0)) return false;
  dir = v / dist;
  return true;
}

// One path's state between tracking steps (see main: paths are regenerated
// within a lane, so the state must live outside any per-path loop).
struct PathState {
  vec3 o, d;   // current ray
  vec3 w;      // path weight (per channel)
  vec3 L;      // radiance gathered so far
  float t;     // distance along the current ray
  uint depth;  // scattering events (medium and surface) so far
  bool fresh;  // the ray changed: recompute the media spans and the surface hit
  // MIS (docs/mis.md): the solid-angle pdfs with which the vertex's
  // continuation (0: camera or light ray) and next-event estimation pick the
  // ray's direction.
  float pdf_dir, p_light;
  // The product of the weight factors by which scatterings that next-event
  // estimation keeps from being absorbed lowered the weight since the last
  // roulette (path_step; docs/mis.md "No absorption events").
  float survival;
  bool has_hit;     // a surface lies ahead on the current ray
  SurfaceHit hit;   // the closest one (t = its distance)
  // Next-event estimation runs as a light ray in this same state: it collects
  // what arrives along the light direction by ratio tracking until it leaves
  // the scene, hits a surface or loses the roulette (weight w = path weight ·
  // f · MIS weight / p_light), then the path goes on with the continuation
  // sampled at the vertex (next_*), one ray segment (free flights up to its
  // event) per path_step like any other ray (docs/rendering.md: divergence).
  bool light_ray;
  float light_T;  // a light ray's ratio-tracking transmittance (max channel) since its last roulette
  // Ratio-tracked continuation (docs/mis.md): 1 while the surface vertex's
  // ray along the continuation is still to come, 2 once it has run; the
  // continuation then collects nothing on its first segment (skip_segment).
  uint continuation_ray;
  bool skip_segment;
  bool next_ends;  // the continuation has no weight or depth left
  vec3 next_o, next_d, next_w;
  float next_pdf_dir, next_p_light;
  // A surface vertex sends integrator.surface_light_samples light rays, one
  // after another: how many are still to come, and what their weights need
  // (the path weight times the albedo at the vertex, the normal on the incident side).
  uint lights_left;
  bool light_pending;  // a light ray ended and lights_left > 0: draw the next one
  vec3 vertex_wa, vertex_n;
  vec4 vertex_norm;  // light_norms at the current vertex, by grid slot (MAX_GRIDS = 4)
  // A medium vertex's light ray is drawn like a surface vertex's, by
  // next_light_ray: its phase mixture (the incident direction, each lobe's
  // share and probability); vertex_wa is then the path weight at the vertex.
  bool vertex_medium;
  vec3 vertex_d_in;
  vec3 vertex_share[MEDIA_N];
  float vertex_q[MEDIA_N];
  // A light ray toward delta light `delta_light` (LIGHT_COUNT: none): it
  // collects nothing on its way (skip_segment) and adds its weight where it
  // reaches the light (a point or spot: path_begin puts a hit there; a
  // distant light: escaping).
  uint delta_light;
};

// Radiance of a ray that leaves the scene: the environment map (+Z up,
// docs/lights.md), or the constant background.
vec3 escaped_radiance(vec3 d) {
  const vec3 sky = HAS_ENVIRONMENT ? env_radiance(environment, d) : frame.background.rgb;
  return LIGHT_COUNT > 0u ? sky + disc_lights_radiance(d) : sky;
}

// The ray leaves the scene: add what it sees, MIS-weighted. A light ray
// toward a delta distant light has reached it.
void escape(inout PathState p) {
  if (LIGHT_COUNT > 0u && p.delta_light < LIGHT_COUNT) {
    if (analytic_lights[p.delta_light].kind.x == LIGHT_DISTANT) p.L += p.w;
    return;
  }
  if (!p.skip_segment) p.L += unidirectional_weight(p.pdf_dir, p.p_light) * p.w * escaped_radiance(p.d);
}

// Start a new ray at a vertex, its direction sampled with solid-angle pdf pdf_dir.
void new_ray(inout PathState p, vec3 o, vec3 d, float pdf_dir, float p_light) {
  p.o = o;
  p.d = d;
  p.fresh = true;
  p.pdf_dir = pdf_dir;
  p.p_light = p_light;
  p.light_T = 1.0;
  p.skip_segment = false;
  p.delta_light = LIGHT_COUNT;
}

// The continuation's solid-angle pdf of a direction that the vertex's lobe
// draws with pdf_own and the lights with p_light (docs/mis.md eq. 5).
float continuation_pdf(float pdf_own, float p_light) {
  const float c = frame.lights.y;
  return c * pdf_own + (1.0 - c) * p_light;
}

// The phase function of a scattering mixture from d_in toward w: its value
// f = Σ_i share_i·HG_i (per channel) and the pdf with which the vertex samples
// w, Σ_i q_i·HG_i (lobe i picked with probability q_i).
void phase_mixture(vec3 d_in, vec3 w, vec3 share[MEDIA_N], float q[MEDIA_N], out vec3 f, out float pdf) {
  f = vec3(0.0);
  pdf = 0.0;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    float hg = hg_pdf(dot(d_in, w), media[i].sigma_s.w);
    f += share[i] * hg;
    pdf += q[i] * hg;
  }
}

// The next of a vertex's light rays (docs/mis.md "Several light samples"),
// drawn by path_begin: a light direction from the vertex, its
// weight w·f·MIS weight / (n·p_light) for the vertex's n light samples (a
// surface's frame.lights.z, a medium vertex's 1); weight 0 when no light
// direction was found (the ray then ends at once). The only copy of the
// light-sampling code: llvmpipe runs every copy for the whole SIMD group.
// One draw per call and no loop: Mesa 22.3's llvmpipe returned false from a
// `return true` inside this function's former retry loop for some lanes of a
// SIMD group (measured: 46 % of the found light rays lost, the furnace 2 % dark).
void next_light_ray(inout PathState p, inout uint rng) {
  const float n = p.vertex_medium ? 1.0 : frame.lights.z;
  --p.lights_left;
  vec3 dir, delta_w;
  uint delta_light;
  vec3 w = vec3(0.0);
  if (sample_light_direction(p.next_o, p.vertex_norm, rng, dir, delta_w, delta_light)) {
    vec3 f;
    float pdf_own;
    if (p.vertex_medium) {
      phase_mixture(p.vertex_d_in, dir, p.vertex_share, p.vertex_q, f, pdf_own);
    } else {
      pdf_own = max(dot(p.vertex_n, dir), 0.0) * (1.0 / PI);  // Lambertian: f·cos = albedo·cos/π
      f = vec3(pdf_own);
    }
    if (LIGHT_COUNT > 0u && delta_light < LIGHT_COUNT) {
      w = p.vertex_wa * f * delta_w / n;  // no MIS: only light sampling finds a delta light
    } else {
      const float p_l = pdf_own > 0.0 && max3(p.vertex_wa * f) > 0.0 ? light_direction_pdf(p.next_o, p.vertex_norm, dir) : 0.0;
      if (p_l > 0.0) w = p.vertex_wa * f * (light_weight(n * p_l, continuation_pdf(pdf_own, p_l)) / (n * p_l));
    }
  }
  p.w = w;
  new_ray(p, p.next_o, dir, 0.0, 0.0);
  if (LIGHT_COUNT > 0u && delta_light < LIGHT_COUNT) {
    p.delta_light = delta_light;
    p.skip_segment = true;
  }
}

// The vertex's light rays are done: the continuation starts (true: the path
// has ended). With a ratio-tracked continuation, first one more light ray
// along the continuation's direction, with its weight and MIS weight: it
// collects the continuation's first segment, which the path then skips.
bool hand_over(inout PathState p) {
  if (p.next_ends) {
    p.light_ray = false;
    return true;
  }
  if (p.continuation_ray == 1u) {
    p.continuation_ray = 2u;
    p.w = p.next_w * unidirectional_weight(p.next_pdf_dir, p.next_p_light);
    new_ray(p, p.next_o, p.next_d, 0.0, 0.0);
    return false;
  }
  p.light_ray = false;
  p.w = p.next_w;
  new_ray(p, p.next_o, p.next_d, p.next_pdf_dir, p.next_p_light);
  p.skip_segment = p.continuation_ray == 2u;
  p.continuation_ray = 0u;
  return false;
}

// The current ray ends. A light ray hands over to the vertex's next light ray
// or to the continuation it sampled; returns true when the path has ended. The
// next light ray is drawn by path_begin (light_pending), in one
// place: inlined at each of ray_ends' call sites, the light sampling code made
// the shader 2× slower on llvmpipe.
bool ray_ends(inout PathState p) {
  if (!NEE || !p.light_ray) return true;
  if (p.lights_left > 0u) {
    p.light_pending = true;
    return false;
  }
  return hand_over(p);
}

// Whether a vertex draws its continuation from the lights (with next-event
// estimation, probability 1 − frame.lights.y; docs/mis.md "Guided
// continuation") and, if so, the direction. false with dir unset: its own lobe.
bool continue_toward_light(vec3 o, vec4 norm, inout uint rng, out vec3 dir, out bool none) {
  dir = vec3(0.0, 0.0, 1.0);
  none = false;
  if (!NEE || !GUIDED_CONTINUATION || rng_next(rng) < frame.lights.y) return false;
  vec3 delta_w;
  uint delta_light;
  // A delta light has no direction density: drawing one leaves the
  // continuation without a direction (weight 0), so the continuation's density
  // is still continuation_pdf's.
  none = !sample_light_direction(o, norm, rng, dir, delta_w, delta_light) || delta_light < LIGHT_COUNT;
  return true;
}

// Leave vertex o along d, which the vertex's lobe weights by f with pdf
// pdf_own (the continuation's pdf is the mixture with the lights'). With
// next-event estimation the continuation waits for the vertex's lights_after
// light rays, all drawn by next_light_ray (n_light: the vertex's number of
// light samples, for the MIS weights, eq. 6). Returns true when the path has
// ended.
bool leave_vertex(inout PathState p, vec3 o, vec3 d, vec3 f, float pdf_own, uint n_light, uint lights_after) {
  // "<= 0", not "!(> 0)": a NaN weight goes on and is counted (nonfinite_samples).
  if (!NEE) {
    p.w *= f / pdf_own;
    new_ray(p, o, d, pdf_own, 0.0);
    return max3(p.w) <= 0.0;
  }
  const float n = float(n_light);
  const float p_light_d = max3(f) > 0.0 ? light_direction_pdf(o, p.vertex_norm, d) : 0.0;
  const float p_mix = continuation_pdf(pdf_own, p_light_d);
  const vec3 w = p_mix > 0.0 ? p.w * f / p_mix : vec3(0.0);
  p.next_ends = max3(w) <= 0.0;
  p.next_o = o;
  p.next_d = d;
  p.next_w = w;
  p.next_pdf_dir = p_mix;
  p.next_p_light = n * p_light_d;
  p.lights_left = lights_after;
  // The ratio-tracked continuation: surface vertices only.
  p.continuation_ray = frame.lights.w > 0.0 && lights_after > 0u && !p.vertex_medium ? 1u : 0u;
  p.light_ray = true;
  return ray_ends(p);  // the first light ray, or the continuation
}

// A scattering vertex: a Lambertian bounce at the surface ahead (surface;
// weight × albedo, as cosine sampling's pdf cancels the cosine and 1/π, the
// new direction on the side the ray came from: surfaces are two-sided) or a
// real scattering collision at x in the media. Returns true when the path
// ends. Both kinds share one copy of the light code (the receiver
// normalisers, leave_vertex's light pdf; their light rays are drawn by
// next_light_ray): llvmpipe runs every copy for the whole SIMD group, and one
// more copy of light_norms,
// sample_light_direction or light_direction_pdf cost fire_ground 22, 10 and
// 16 % (docs/benchmarks.md "One copy of the vertex's light code").
bool scatter_vertex(inout PathState p, bool surface, vec3 x, vec3 sigma_s, float sigma_bar, float p_s,
                    float rho[MEDIA_N], inout uint rng, inout PathStats stats) {
  vec3 o = x, n = vec3(0.0), albedo = vec3(0.0);
  vec3 share[MEDIA_N];
  float q[MEDIA_N];
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    share[i] = vec3(0.0);
    q[i] = 0.0;
  }
  if (surface) {
    SurfaceInteraction si = surface_interaction(p.o, p.d, p.hit);
    stats.events += 1.0;
    if (p.depth >= frame.image.w) return true;  // max_depth reached
    ++p.depth;
    GpuMaterial m = surface_materials[si.material];
    albedo = m.albedo.rgb;
    if (ALBEDO_TEXTURE_COUNT > 0u && m.info.x != NO_TEXTURE)
      albedo *= albedo_texture_at(m.info.x, vec2(si.uv.x, 1.0 - si.uv.y));  // OBJ v=0 at the bottom
    n = dot(si.normal, p.d) < 0.0 ? si.normal : -si.normal;
    o = offset_ray_origin(si.position, n);
  } else {
    if (p.depth >= frame.image.w) return true;  // max_depth reached
    ++p.depth;
    const float w_before = max3(p.w);
    p.w *= sigma_s / (sigma_bar * p_s);
    if (NEE && COLLISION_ESTIMATOR) {
      // Russian roulette for what absorption no longer ends: once the factors
      // that kept this path alive have lowered its weight below
      // SCATTER_ROULETTE_BELOW of what it was, survive with probability
      // survival / SCATTER_ROULETTE_BELOW, reweighted.
      p.survival *= max3(p.w) / w_before;
      const float q_survive = p.survival / SCATTER_ROULETTE_BELOW;
      if (q_survive < 1.0) {
        if (rng_next(rng) >= q_survive) return true;
        p.w /= q_survive;
        p.survival = SCATTER_ROULETTE_BELOW;
      }
    }
    // Phase function of the mixture f = Σ_i share_i·HG_i, share_i = σs_i/σs (per
    // channel): sample lobe i with q_i ∝ avg(share_i ⊙ w); the direction's pdf
    // is the mixture's, Σ_i q_i·HG_i, and the weight f/pdf.
    vec3 inv_sigma_s = 1.0 / max(sigma_s, vec3(1e-30));
    float total = 0.0;
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      share[i] = rho[i] * media[i].sigma_s.rgb * inv_sigma_s;
      q[i] = avg3(share[i] * p.w);
      total += q[i];
    }
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) q[i] /= total;
  }
  if (NEE) light_norms(o, p.vertex_norm);
  vec3 d;
  bool none;
  if (!continue_toward_light(o, p.vertex_norm, rng, d, none)) {
    if (surface) {
      d = sample_cosine_hemisphere(n, vec2(rng_next(rng), rng_next(rng)));
    } else {
      float pick = rng_next(rng), acc = 0.0, g = 0.0;
      for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
        if (q[i] <= 0.0) continue;
        acc += q[i];
        g = media[i].sigma_s.w;
        if (pick < acc) break;
      }
      d = sample_hg(p.d, g, vec2(rng_next(rng), rng_next(rng)));
    }
  }
  vec3 f;
  float pdf_own;
  uint n_light = 1u, lights_after = 0u;
  if (surface) {
    // f·cos = albedo·cos/π, BSDF pdf cos/π.
    pdf_own = none ? 0.0 : max(dot(n, d), 0.0) * (1.0 / PI);
    f = albedo * pdf_own;
    p.vertex_medium = false;
    p.vertex_n = n;
    p.vertex_wa = p.w * albedo;
    lights_after = NEE && max3(p.w * albedo) > 0.0 ? uint(frame.lights.z) : 0u;
    n_light = max(lights_after, 1u);
  } else {
    phase_mixture(p.d, d, share, q, f, pdf_own);
    if (none) f = vec3(0.0);
    if (NEE) {  // its one light ray, drawn by next_light_ray with this phase mixture
      p.vertex_medium = true;
      p.vertex_wa = p.w;
      p.vertex_d_in = p.d;
      for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
        p.vertex_share[i] = share[i];
        p.vertex_q[i] = q[i];
      }
      lights_after = 1u;
    }
  }
  return leave_vertex(p, o, d, f, pdf_own, n_light, lights_after);
}

// The events path_track ends a ray segment with (EVENT_NONE: EARLY_EVENT_EXIT
// left the free-flight loop before this lane found its event).
const uint EVENT_NONE = 0u, EVENT_ESCAPE = 1u, EVENT_SURFACE = 2u, EVENT_ABSORB = 3u, EVENT_SCATTER = 4u,
           EVENT_END = 5u;
// What path_event needs of the real collision path_track found.
struct Collision {
  vec3 x, sigma_s;
  float sigma_bar, p_a, p_s;
};
// path_begin's answers: the ray is ready for free flights, or it ended before
// any (the path goes on with its next ray, or has ended).
const int RAY_READY = -1, RAY_ENDED = 0, PATH_ENDED = 1;

// Sphere lights that a fresh ray meets before its surface hit, and where a
// light ray toward a point or spot light reaches it: a hit of kind
// SURFACE_HIT_LIGHT (primitive: the light).
void lights_on_ray(inout PathState p) {
  float t = p.has_hit ? p.hit.t : INF;
  uint light = intersect_sphere_lights(p.o, p.d, t);
  if (p.delta_light < LIGHT_COUNT && analytic_lights[p.delta_light].kind.x != LIGHT_DISTANT) {
    const float r = length(analytic_lights[p.delta_light].position.xyz - p.o);
    if (r < t) {
      t = r;
      light = p.delta_light;
    }
  }
  if (light == LIGHT_COUNT) return;
  p.has_hit = true;
  p.hit.t = t;
  p.hit.kind = SURFACE_HIT_LIGHT;
  p.hit.primitive = light;
}

// The start of a path_step: the vertex's next light ray when one is pending,
// and a fresh ray's media spans and surface hit.
int path_begin(inout PathState p, inout vec2 span[MEDIA_N], inout uint rng) {
  if (NEE && p.light_pending) {
    p.light_pending = false;
    next_light_ray(p, rng);
    if (max3(p.w) <= 0.0) return ray_ends(p) ? PATH_ENDED : RAY_ENDED;  // no light this time: the next one, or the continuation
  }
  if (p.fresh) {
    bool any_hit;
    media_spans(p.o, p.d, span, any_hit);
    p.has_hit = HAS_SURFACES && intersect_surfaces(p.o, p.d, 1e30, p.hit);
    if (LIGHT_COUNT > 0u) lights_on_ray(p);
    p.fresh = false;
    p.t = 0.0;
    if (!any_hit && !p.has_hit) {
      escape(p);
      return ray_ends(p) ? PATH_ENDED : RAY_ENDED;
    }
    // Move the origin to the first thing the ray reaches, so every later
    // position o + t·d is computed with a small t: from a camera 1e4 units
    // away, o + t·d would carry ~1e-3 units of float error into every lookup
    // and DDA step.
    float t0 = p.has_hit ? p.hit.t : INF;
    for (uint i = 0u; i < MEDIUM_COUNT; ++i)
      if (span[i].y > 0.0) t0 = min(t0, span[i].x);
    if (t0 > 0.0 && !isinf(t0)) {
      p.o += t0 * p.d;
      for (uint i = 0u; i < MEDIUM_COUNT; ++i)
        if (span[i].y > 0.0) span[i] -= t0;
      if (p.has_hit) p.hit.t -= t0;
    }
  }
  return RAY_READY;
}

// Free flights along the current ray until its event (path_step's loop).
//
// Delta tracking against a piecewise-constant majorant: the ray is split at
// media boundaries and majorant-cell faces, and free flights restart at each
// (memoryless). RGB sigma is handled by spectral tracking (Kutz et al. 2017,
// "Spectral and Decomposition Tracking", history-aware averaged probabilities):
// distances are sampled with the grey majorant sigma_bar, and event x (absorb /
// scatter / null) is chosen with P_x = avg(sigma_x ⊙ w) / (sigma_bar·avg(w)); the
// path weight w then picks up sigma_x / (sigma_bar·P_x) per channel. For grey
// media every factor is 1 and this is plain delta tracking.
uint path_track(inout PathState p, vec2 span[MEDIA_N], inout uint rng, inout PathStats stats, out Collision c_out,
                out float rho[MEDIA_N], out float temperature_value[MEDIA_N]) {
  // Free flights, until the ray meets what needs more than a density lookup:
  // a surface, a real event, the end of the media, a light ray's lost
  // roulette. The cheap steps loop here and the event code below runs once per
  // event: llvmpipe runs every branch for the whole SIMD group (masked), so
  // with one step per path_step call each null collision also paid for the
  // vertex code (while-while, Aila & Laine 2009). No return inside the loop
  // (docs/mis.md: llvmpipe lost returns from inside loops).
  //
  // Each pass of the loop is one free flight of every lane still looking for
  // its event (the do-while(false) body: `continue` and `break` there end the
  // flight). The lanes that have theirs wait, masked, for the others: the
  // loop ran at 26–35 % lane use on the lookup-bound scene. With
  // EARLY_EVENT_EXIT the group leaves once half of its lanes are done; the
  // others keep their ray and position and go on at the next call (free
  // flights are memoryless). Each path sees the same random numbers either
  // way, so the image is bit-identical.
  uint event = EVENT_NONE;
  float sigma_bar = 0.0, p_a = 0.0, p_s = 0.0;
  vec3 x = vec3(0.0), sigma_a = vec3(0.0), sigma_s = vec3(0.0);
  for (;;) {
    if (event == EVENT_NONE) do {
      float t_next;
      bool any_ahead;
      sigma_bar = majorant_at(p.o, p.d, p.t, span, t_next, any_ahead);
      if (!any_ahead) t_next = INF;
      // Media beyond the closest surface do not matter: free flights end there.
      const float t_surface = p.has_hit ? p.hit.t : INF;
      if (isinf(t_next) && !p.has_hit) {
        event = EVENT_ESCAPE;
        break;
      }
      const float t_end = min(t_next, t_surface);
      float dt = sigma_bar > 0.0 ? sample_free_flight(sigma_bar, rng_next(rng)) : INF;
      if (p.t + dt >= t_end) {
        if (p.has_hit && t_surface <= t_next) {
          event = EVENT_SURFACE;
          break;
        }
        p.t = t_next;
        continue;
      }
      p.t += dt;
      x = p.o + p.t * p.d;
      coefficients_at(x, p.t, span, sigma_a, sigma_s, rho, temperature_value, stats);
      if (HAS_EMISSION && COLLISION_ESTIMATOR && !p.skip_segment) {
        // Collision estimator (pbrt-v4 volpath): sigma_a·Le/sigma_bar at every tentative collision.
        // With next-event estimation the ray's own MIS weight (light rays: 1). A skipped
        // segment (ratio-tracked continuation) was already collected: no lookup.
        vec3 e = emission_at(x, p.t, span, rho, temperature_value);
        if (max3(e) > 0.0) p.L += (unidirectional_weight(p.pdf_dir, p.p_light) / sigma_bar) * p.w * e;
      }
      vec3 sigma_n = max(vec3(sigma_bar) - sigma_a - sigma_s, vec3(0.0));
      if (NEE && p.light_ray) {
        // Light rays: ratio tracking (docs/mis.md "Light rays"): no event is
        // chosen, the weight takes the null fraction, Russian roulette once the
        // ray's transmittance estimate is below RATIO_TRACKING_ROULETTE_BELOW.
        const vec3 null_fraction = sigma_n / sigma_bar;
        p.w *= null_fraction;
        p.light_T *= max3(null_fraction);
        if (p.light_T < RATIO_TRACKING_ROULETTE_BELOW) {
          if (rng_next(rng) >= p.light_T) {
            event = EVENT_END;
            break;
          }
          p.w /= p.light_T;
          p.light_T = 1.0;
        }
        continue;
      }
      float c = sigma_bar * avg3(p.w);
      p_a = avg3(sigma_a * p.w) / c;
      p_s = HAS_SCATTERING ? avg3(sigma_s * p.w) / c : 0.0;
      // With next-event estimation a real collision scatters whenever it can
      // (docs/mis.md "No absorption events"): the collision estimator has already
      // collected the emission here, and the scattering's weight
      // sigma_s / (sigma_bar·(P_a + P_s)) keeps the expectation.
      if (NEE && COLLISION_ESTIMATOR && p_s > 0.0) {
        p_s += p_a;
        p_a = 0.0;
      }
      float u = rng_next(rng);
      if (u < p_a) {
        event = EVENT_ABSORB;
        break;
      }
      if (HAS_SCATTERING && u < p_a + p_s) {
        event = EVENT_SCATTER;
        break;
      }
      p.w *= sigma_n / (sigma_bar * (1.0 - p_a - p_s));
      if (max3(p.w) <= 0.0) event = EVENT_END;
    } while (false);
    if (!EARLY_EVENT_EXIT) {
      if (event != EVENT_NONE) break;
    } else {
      // Uniform across the group: every active lane counts the same ballots.
      const uint lanes = subgroupBallotBitCount(subgroupBallot(true));
      const uint tracking = subgroupBallotBitCount(subgroupBallot(event == EVENT_NONE));
      if (2u * tracking <= lanes) break;
    }
  }
  c_out = Collision(x, sigma_s, sigma_bar, p_a, p_s);
  return event;
}

// What a ray segment's event does (path_step's end); true when the path has ended.
bool path_event(inout PathState p, vec2 span[MEDIA_N], uint event, Collision c, float rho[MEDIA_N],
                float temperature_value[MEDIA_N], inout uint rng, inout PathStats stats) {
  const vec3 x = c.x, sigma_s = c.sigma_s;
  const float sigma_bar = c.sigma_bar, p_a = c.p_a, p_s = c.p_s;
  if (event == EVENT_ESCAPE) {
    escape(p);
    return ray_ends(p);
  }
  if (LIGHT_COUNT > 0u && event == EVENT_SURFACE && p.hit.kind == SURFACE_HIT_LIGHT) {
    // A delta light ray arrives (its weight holds f·I/(r²·P)); any other ray
    // sees the sphere light's radiance, MIS-weighted, and ends: it is opaque.
    if (p.hit.primitive == p.delta_light) p.L += p.w;
    else if (!p.skip_segment)
      p.L += unidirectional_weight(p.pdf_dir, p.p_light) * p.w *
             sphere_light_radiance(analytic_lights[p.hit.primitive], p.o + p.hit.t * p.d, p.d);
    return ray_ends(p);
  }
  if (event == EVENT_END || (event == EVENT_SURFACE && NEE && p.light_ray)) return ray_ends(p);
  const bool surface = HAS_SURFACES && event == EVENT_SURFACE;
  if (!surface) {
    stats.events += 1.0;
    if (event == EVENT_ABSORB) {
      // Absorbed: the absorption estimator collects sigma_a·Le / (sigma_bar·P_a).
      if (HAS_EMISSION && !COLLISION_ESTIMATOR)
        p.L += p.w * emission_at(x, p.t, span, rho, temperature_value) / (sigma_bar * p_a);
      return ray_ends(p);
    }
  }
  return scatter_vertex(p, surface, x, sigma_s, sigma_bar, p_s, rho, rng, stats);
}

// One step of delta tracking along one path: its next ray if needed, free
// flights, the event. Returns true when the path has ended (p.L is then final).
bool path_step(inout PathState p, inout vec2 span[MEDIA_N], inout uint rng, inout PathStats stats) {
  const int begun = path_begin(p, span, rng);
  if (begun != RAY_READY) return begun == PATH_ENDED;
  Collision c;
  float rho[MEDIA_N], temperature_value[MEDIA_N];
  const uint event = path_track(p, span, rng, stats, c, rho, temperature_value);
  if (event == EVENT_NONE) return false;  // EARLY_EVENT_EXIT: still in free flight
  return path_event(p, span, event, c, rho, temperature_value, rng, stats);
}

// Start p as a camera ray through pixel `pixel` for sample `k`, with that
// sample's random stream (p is filled in place: PathState holds arrays sized
// by a specialisation constant, which GLSL cannot copy).
void camera_path(uvec2 pixel, uint k, out uint rng, inout PathState p) {
  uint width = frame.image.x, height = frame.image.y;
  rng = rng_init(frame.sampling.x, frame.sampling.y, pixel.y * width + pixel.x, k);
  // Box filter: jitter uniformly inside the pixel; pixel (0,0) is top-left.
  vec2 jitter = vec2(rng_next(rng), rng_next(rng));
  vec2 ndc = vec2(2.0 * (float(pixel.x) + jitter.x) / float(width) - 1.0,
                  1.0 - 2.0 * (float(pixel.y) + jitter.y) / float(height));
  float tan_half = frame.camera_position.w, aspect = frame.camera_forward.w;
  vec3 d = normalize(frame.camera_forward.xyz + ndc.x * tan_half * aspect * frame.camera_right.xyz +
                     ndc.y * tan_half * frame.camera_up.xyz);
  p.o = frame.camera_position.xyz;
  p.d = d;
  p.w = vec3(1.0);
  p.L = vec3(0.0);
  p.t = 0.0;
  p.depth = 0u;
  p.fresh = true;
  p.has_hit = false;
  p.pdf_dir = 0.0;
  p.p_light = 0.0;
  p.survival = 1.0;
  p.light_ray = false;
  p.light_T = 1.0;
  p.continuation_ray = 0u;
  p.skip_segment = false;
  p.next_ends = true;
  p.next_o = p.next_d = p.next_w = vec3(0.0);
  p.next_pdf_dir = p.next_p_light = 0.0;
  p.lights_left = 0u;
  p.vertex_wa = p.vertex_n = vec3(0.0);
  p.light_pending = false;
  p.delta_light = LIGHT_COUNT;
  p.vertex_norm = vec4(0.0);
  p.vertex_medium = false;
  p.vertex_d_in = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    p.vertex_share[i] = vec3(0.0);
    p.vertex_q[i] = 0.0;
  }
}

// One Kahan (1965) summation step: s − c carries the sum of the x's to about
// twice float precision (`precise` stops the compiler reassociating). Used for
// the samples within a pass (64 float additions lose up to ~2e-6 otherwise)
// and for the passes in the accumulation buffer.
void kahan_add(inout vec3 s, inout vec3 c, vec3 x) {
  precise vec3 y = x - c;
  precise vec3 t = s + y;
  c = (t - s) - y;
  s = t;
}

// One sample's radiance into the pass's sums (NaN and Inf fail the
// comparison too: counted, and recorded as 0).
void add_sample(vec3 L, inout vec3 pass_sum, inout vec3 pass_sum_c, inout vec3 pass_sq, inout vec3 pass_sq_c,
                inout float nonfinite) {
  if (!all(lessThanEqual(abs(L), vec3(MAX_SAMPLE_RADIANCE)))) {
    nonfinite += 1.0;
    L = vec3(0.0);
  }
  kahan_add(pass_sum, pass_sum_c, L);
  kahan_add(pass_sq, pass_sq_c, L * L);
}

// A pass's sums into the pixel's accumulation, Kahan-compensated across passes.
void add_pass(uint pixel_index, vec3 pass_sum, vec3 pass_sum_c, vec3 pass_sq, vec3 pass_sq_c, PathStats stats,
              float nonfinite) {
  AccumTexel a = accum[pixel_index];
  precise vec4 y = vec4(pass_sum - pass_sum_c, stats.events) - a.sum_c;
  precise vec4 s = a.sum + y;
  a.sum_c = (s - a.sum) - y;
  a.sum = s;
  precise vec3 y2 = (pass_sq - pass_sq_c) - a.sum_sq_c.xyz;
  precise vec3 s2 = a.sum_sq.xyz + y2;
  a.sum_sq_c.xyz = (s2 - a.sum_sq.xyz) - y2;
  a.sum_sq.xyz = s2;
  a.sum_sq.w += stats.lookups;
  a.sum_sq_c.w += nonfinite;
  accum[pixel_index] = a;
}

#include "wavefront.glsl"

void main() {
  if (WAVEFRONT_STAGE != WAVEFRONT_NONE) {
    wavefront_main();
    return;
  }
  uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, pass_constants.row_begin);
  uint width = frame.image.x, height = frame.image.y;
  if (pixel.x >= width || pixel.y >= min(height, pass_constants.row_end)) return;
  uint pixel_index = pixel.y * width + pixel.x;

  vec3 pass_sum = vec3(0.0), pass_sq = vec3(0.0);
  vec3 pass_sum_c = vec3(0.0), pass_sq_c = vec3(0.0);  // their Kahan compensations
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
    }
  } else {
    // Paths are regenerated within the lane: one loop iteration is one tracking
    // step, and a lane whose path ends starts its next sample at once instead of
    // idling until the longest path of its SIMD group ends (docs/rendering.md:
    // divergence halves throughput). Each sample keeps its own random stream, so
    // the result does not depend on the schedule.
    //
    // llvmpipe ends every loop of the invocation once all its loops together
    // have run 65535 iterations (per SIMD group; PassStatus in gpu_types.h):
    // unfinished samples are reported below and the host redoes the pass in
    // smaller ones. (The nested loops are from when the limit was thought to
    // be per loop; they cost nothing.)
    uint rng;
    PathState p;
    camera_path(pixel, k, rng, p);
    vec2 span[MEDIA_N];
    while (k < last) {
      for (uint n = 0u; n < 16384u && k < last; ++n) {
        if (!path_step(p, span, rng, stats)) continue;
        add_sample(p.L, pass_sum, pass_sum_c, pass_sq, pass_sq_c, nonfinite);
        if (++k < last) camera_path(pixel, k, rng, p);
      }
    }
  }

  if (k < last) {  // the pass ran out of loop budget: the host discards and redoes it
    atomicAdd(pass_status.counts.x, last - k);
    return;
  }

  add_pass(pixel_index, pass_sum, pass_sum_c, pass_sq, pass_sq_c, stats, nonfinite);
}
