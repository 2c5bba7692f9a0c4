// render.comp's specialisation constants (a scene compiles only the code it
// uses) and descriptor bindings (the BINDING_* list in shared/gpu_types.h),
// with the small helpers every other part of the integrator uses.
// Specialisation: a scene without grids/scattering/emission compiles none of that code.
layout(constant_id = SPEC_HAS_GRIDS) const bool HAS_GRIDS = true;
layout(constant_id = SPEC_HAS_ANALYTIC_MEDIA) const bool HAS_ANALYTIC_MEDIA = true;
layout(constant_id = SPEC_HAS_SCATTERING) const bool HAS_SCATTERING = true;
layout(constant_id = SPEC_HAS_EMISSION) const bool HAS_EMISSION = true;
layout(constant_id = SPEC_COLLISION_ESTIMATOR) const bool COLLISION_ESTIMATOR = false;
layout(constant_id = SPEC_DEBUG_MODE) const uint DEBUG_MODE = DEBUG_NONE;
// The per-medium loops' trip count (docs/rendering.md "llvmpipe workarounds": constant trip counts).
layout(constant_id = SPEC_MEDIUM_COUNT) const uint MEDIUM_COUNT = 1;
const uint MEDIA_N = MEDIUM_COUNT > 0u ? MEDIUM_COUNT : 1u;  // array size (never 0)
// With a single grid medium the texture switches fold to slot 0 (docs/rendering.md "llvmpipe workarounds": every branch runs).
layout(constant_id = SPEC_GRID_COUNT) const uint GRID_COUNT = 1;
layout(constant_id = SPEC_HAS_SURFACES) const bool HAS_SURFACES = false;
layout(constant_id = SPEC_SURFACE_SHAPE_COUNT) const uint SURFACE_SHAPE_COUNT = 0;
layout(constant_id = SPEC_SURFACE_HAS_TRIANGLES) const bool SURFACE_HAS_TRIANGLES = false;
layout(constant_id = SPEC_ALBEDO_TEXTURE_COUNT) const uint ALBEDO_TEXTURE_COUNT = MAX_TEXTURES;
layout(constant_id = SPEC_HAS_ENVIRONMENT) const bool HAS_ENVIRONMENT = false;
layout(constant_id = SPEC_LIGHT_STRATEGY) const uint LIGHT_STRATEGY = LIGHT_STRATEGY_BSDF;
const bool NEE = LIGHT_STRATEGY != LIGHT_STRATEGY_BSDF;  // next-event estimation (with the collision estimator)
// Continuations drawn from the lights with probability 1 − frame.p_continue_own; off
// (frame.p_continue_own = 1) compiles that code out.
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
// film.aovs: the light layers and first-hit features; off compiles their code out.
layout(constant_id = SPEC_AOVS) const bool AOVS = false;

// The frame, the media and the light headers are storage buffers, though every
// lane reads the same entries: lavapipe (Mesa 22.x) inlines uniform-block and
// push-constant values that alone decide a branch or a loop count (say
// frame.p_env > 0, a medium's shape) and JIT-compiles a new variant of this
// shader every time a pass binds them, never freed: a compile and ~0.5 MB per
// pass (docs/robustness.md "Constant memory over a long sequence"). Values in
// storage buffers are never inlined. std140 keeps the host's layouts.
layout(std140, set = 0, binding = BINDING_FRAME) readonly buffer FrameBlock { FrameConstants frame; };
layout(std140, set = 0, binding = BINDING_MEDIA) readonly buffer MediaBlock { GpuMedium media[MAX_MEDIA]; };
layout(std430, set = 0, binding = BINDING_ACCUM) buffer AccumBlock { AccumTexel accum[]; };
layout(std430, set = 0, binding = BINDING_ALPHA) buffer AlphaBlock { AlphaTexel alpha_accum[]; };
layout(std430, set = 0, binding = BINDING_AOV_LIGHTS) buffer AovLightBlock { AovLightTexel aov_lights[]; };
layout(std430, set = 0, binding = BINDING_AOV_FEATURES) buffer AovFeatureBlock { AovFeatureTexel aov_features[]; };
layout(std430, set = 0, binding = BINDING_GUIDE_POINTS) buffer GuidePointBlock { vec4 guide_points[]; };
// Where guide_points holds the guide at pixel corner c (pixel c's top-left
// corner; c.x ≤ width, c.y ≤ height) and at pixel p's centre: the corners
// row by row, then the centres (guide.comp writes them, accumulation.glsl
// add_pixel_guide reads them).
uint guide_corner_index(uvec2 c) { return c.y * (frame.width + 1u) + c.x; }
uint guide_centre_index(uvec2 p) { return (frame.width + 1u) * (frame.height + 1u) + p.y * frame.width + p.x; }
// The grids stay a uniform block: the free-flight loop reads them every step,
// where a uniform load is one scalar read and a storage buffer's a per-lane
// gather (as a storage buffer they made assets/scenes/fire.json render 1.8×
// slower). lavapipe inlines none of their values (measured: one compile per
// pipeline with dense, sparse and several grids); should a change make a
// grid value alone decide a branch, the memory tests in
// tests/vulkan/sequence_memory_test.cpp fail.
layout(std140, set = 0, binding = BINDING_GRIDS) uniform GridBlock { GpuGrid grids[MAX_GRIDS]; };
// A uniform texel buffer, not a storage buffer: on lavapipe a texel fetch is
// the cheaper gather, and the free-flight loop reads a cell every step
// (docs/rendering.md "llvmpipe workarounds": texel buffers for gathers).
layout(set = 0, binding = BINDING_MAJORANTS) uniform samplerBuffer majorant_tex;
float majorant_value(uint index) { return texelFetch(majorant_tex, int(index)).r; }
layout(set = 0, binding = BINDING_DENSITY) uniform sampler3D density_tex[MAX_GRIDS];
layout(set = 0, binding = BINDING_TEMPERATURE) uniform sampler3D temperature_tex[MAX_GRIDS];
layout(set = 0, binding = BINDING_BLACKBODY) uniform sampler1D blackbody_tex[MAX_GRIDS];
// Free flights read the density at one texel of its trilinear footprint, from
// these texel buffers (media.glsl stochastic_density); false: by the sampler.
layout(constant_id = SPEC_STOCHASTIC_DENSITY) const bool STOCHASTIC_DENSITY = false;
layout(set = 0, binding = BINDING_DENSITY_TEXELS) uniform samplerBuffer density_texels[MAX_GRIDS];
// Some grid is a NanoVDB tree in sparse_tex (shaders/sparse.glsl); false: none of that code.
layout(constant_id = SPEC_SPARSE_GRIDS) const bool SPARSE_GRIDS = false;
layout(set = 0, binding = BINDING_SPARSE) uniform usamplerBuffer sparse_tex;
#include "sparse.glsl"
// A storage buffer, not push constants, for the same reason (vk::ParameterBuffer).
layout(std430, set = 0, binding = BINDING_PASS) readonly buffer PassBlock { PassConstants pass_constants; };
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
layout(std140, set = 0, binding = BINDING_ENV_HEADER) readonly buffer EnvHeaderBlock { GpuEnvironment environment; };
#define LIGHTS_EMISSION
layout(std430, set = 0, binding = BINDING_EMISSION_CDF) readonly buffer EmissionCdfBlock { float emission_cdf[]; };
layout(std430, set = 0, binding = BINDING_EMISSION_CELLS) readonly buffer EmissionCellBlock { uint emission_cells[]; };
layout(std430, set = 0, binding = BINDING_EMISSION_PMF) readonly buffer EmissionPmfBlock { float emission_pmf[]; };
layout(std430, set = 0, binding = BINDING_EMISSION_CLUSTERS) readonly buffer EmissionClusterBlock {
  GpuEmissionCluster emission_clusters[];
};
layout(std140, set = 0, binding = BINDING_EMISSION_HEADERS) readonly buffer EmissionHeaderBlock {
  GpuEmissionCdf emission_lights[MAX_GRIDS];  // by grid slot
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
// the test and the analytic code compile out (docs/rendering.md "llvmpipe workarounds": every branch runs).
bool is_grid(GpuMedium m) { return HAS_GRIDS && (!HAS_ANALYTIC_MEDIA || m.shape == SHAPE_GRID); }

struct PathStats {
  float events;   // real collisions: absorptions + scatterings
  float lookups;  // density texture lookups
};
