// Structs and constants shared by the host (C++) and the shaders (GLSL): the one
// source of truth for data that crosses the boundary. Written in the common subset
// of both languages. Members are vec4/uvec4 or a vec3 followed by a 4-byte
// scalar, so std140, std430 and C++ place them alike; the C++ side
// static_asserts every size and offset below.
#ifndef PYROLUME_GPU_TYPES_H
#define PYROLUME_GPU_TYPES_H

#include "shared/common.h"
#ifdef __cplusplus
namespace pyrolume::gpu {
#endif

PYRO_CONST uint WORKGROUP_SIZE_X = 8;
PYRO_CONST uint WORKGROUP_SIZE_Y = 8;
PYRO_CONST uint MAX_MEDIA = 16;
PYRO_CONST uint MAX_GRIDS = 4;  // grid (vdb) media; each has its own texture slots

// Radiance bounds that keep every float sum finite (docs/robustness.md,
// "Finite by construction"). A sample beyond MAX_SAMPLE_RADIANCE in any
// channel is recorded as 0 and counted as non-finite, so 2^24 samples of at
// most 1e15 keep Σ L² below FLT_MAX (3.4e38) on both backends. Emission and
// environment texels past MAX_EMITTED_RADIANCE are refused at load: a
// thousandth of the sample bound, the room path weights (MIS, roulette) need.
PYRO_CONST float MAX_SAMPLE_RADIANCE = 1e15;
PYRO_CONST float MAX_EMITTED_RADIANCE = 1e12;

// Descriptor bindings of render.comp (set 0).
PYRO_CONST uint BINDING_FRAME = 0;     // uniform FrameConstants
PYRO_CONST uint BINDING_MEDIA = 1;     // uniform GpuMedium[MAX_MEDIA]
PYRO_CONST uint BINDING_ACCUM = 2;     // buffer AccumTexel[] (one per pixel)
PYRO_CONST uint BINDING_GRIDS = 3;     // uniform GpuGrid[MAX_GRIDS]
PYRO_CONST uint BINDING_MAJORANTS = 4; // samplerBuffer (r32f): every grid's majorant cells
PYRO_CONST uint BINDING_DENSITY = 5;   // sampler3D[MAX_GRIDS]
PYRO_CONST uint BINDING_TEMPERATURE = 6;  // sampler3D[MAX_GRIDS]
PYRO_CONST uint BINDING_BLACKBODY = 7; // sampler1D[MAX_GRIDS]: blackbody LUT per grid medium
PYRO_CONST uint BINDING_BVH_NODES = 8;       // readonly buffer GpuBvhNode[] (shared/geometry_types.h)
PYRO_CONST uint BINDING_BVH_TRIANGLES = 9;   // readonly buffer GpuTriangle[]
PYRO_CONST uint BINDING_BVH_ATTRIBUTES = 10; // readonly buffer GpuTriangleAttributes[]
PYRO_CONST uint BINDING_SURFACE_SHAPES = 11; // readonly buffer GpuSurfaceShape[]
PYRO_CONST uint BINDING_MATERIALS = 12;      // readonly buffer GpuMaterial[]
PYRO_CONST uint BINDING_TEXTURES = 13;       // sampler2D[MAX_TEXTURES]: albedo textures
PYRO_CONST uint MAX_TEXTURES = 8;
PYRO_CONST uint BINDING_ENV_TEXELS = 14;     // readonly buffer vec4[]: the environment map (shaders/lights.glsl)
PYRO_CONST uint BINDING_ENV_CDF = 15;        // readonly buffer float[]: its sampling CDF
PYRO_CONST uint BINDING_ENV_HEADER = 16;     // uniform GpuEnvironment (shared/light_types.h)
PYRO_CONST uint BINDING_EMISSION_CDF = 17;     // readonly buffer float[]: every emissive grid's emission CDF
PYRO_CONST uint BINDING_EMISSION_CELLS = 18;   // readonly buffer uint[]: the cells of its entries
PYRO_CONST uint BINDING_EMISSION_PMF = 19;     // readonly buffer float[]: per-cell probabilities
PYRO_CONST uint BINDING_EMISSION_HEADERS = 20; // uniform GpuEmissionCdf[MAX_GRIDS], by grid slot
PYRO_CONST uint BINDING_PASS_STATUS = 21;      // buffer PassStatus: what the pass could not finish
PYRO_CONST uint BINDING_EMISSION_CLUSTERS = 22; // readonly buffer GpuEmissionCluster[]: their clusters
PYRO_CONST uint BINDING_PATHS = 23;    // uimageBuffer (rgba32ui): the wavefront's path states (shaders/wavefront.glsl path_io)
PYRO_CONST uint BINDING_QUEUES = 24;   // buffer WavefrontQueues, then its queues of path slots
PYRO_CONST uint BINDING_LIGHTS = 25;    // readonly buffer GpuLight[]: the scene's analytic lights (shared/light_types.h)
PYRO_CONST uint BINDING_ALPHA = 26;    // buffer AlphaTexel[] (one per pixel)
PYRO_CONST uint BINDING_AOV_LIGHTS = 27;    // buffer AovLightTexel[] (one per pixel; film.aovs)
PYRO_CONST uint BINDING_AOV_FEATURES = 28;  // buffer AovFeatureTexel[] (one per pixel; film.aovs)
PYRO_CONST uint BINDING_SPARSE = 29;  // usamplerBuffer (rgba32ui): every sparse grid's NanoVDB tree and leaf table (shaders/sparse.glsl)
PYRO_CONST uint BINDING_DENSITY_TEXELS = 30;  // samplerBuffer[MAX_GRIDS] (r16f or r32f): each dense grid's density texels, for stochastic lookups
PYRO_CONST uint BINDING_PASS = 31;  // readonly buffer PassConstants: this dispatch's samples and rows (not push constants: vk::ParameterBuffer)
PYRO_CONST uint BINDING_GUIDE_POINTS = 32;  // buffer vec4[(width + 1)·(height + 1) + width·height]: the guide at the pixels' corners, then centres (film.aovs; guide.comp)
PYRO_CONST uint SPARSE_ZERO_LEAF = 32;  // (not a binding) byte offset of 512 zero floats in the BINDING_SPARSE buffer: the values of every absent leaf

// Specialisation constants of render.comp: a scene pays only for what it uses.
PYRO_CONST uint SPEC_HAS_GRIDS = 0;
PYRO_CONST uint SPEC_HAS_SCATTERING = 1;
PYRO_CONST uint SPEC_HAS_EMISSION = 2;
PYRO_CONST uint SPEC_COLLISION_ESTIMATOR = 3;
PYRO_CONST uint SPEC_DEBUG_MODE = 4;
PYRO_CONST uint SPEC_MEDIUM_COUNT = 5;  // loops over media get a constant trip count
PYRO_CONST uint SPEC_GRID_COUNT = 6;
PYRO_CONST uint SPEC_HAS_SURFACES = 7;
PYRO_CONST uint SPEC_SURFACE_SHAPE_COUNT = 8;
PYRO_CONST uint SPEC_SURFACE_HAS_TRIANGLES = 9;
PYRO_CONST uint SPEC_HAS_ENVIRONMENT = 10;
PYRO_CONST uint SPEC_LIGHT_STRATEGY = 11;  // LIGHT_STRATEGY_*: next-event estimation and MIS (docs/mis.md)
PYRO_CONST uint SPEC_GUIDED_CONTINUATION = 12;  // some continuations are drawn from the lights (LightSelection::p_continue_own < 1)
PYRO_CONST uint SPEC_EARLY_EVENT_EXIT = 13;  // free flights leave once half the SIMD group has its event (render.comp path_track)
PYRO_CONST uint SPEC_HAS_ANALYTIC_MEDIA = 14;  // a sphere or box medium (else every medium is a grid)
PYRO_CONST uint SPEC_ALBEDO_TEXTURE_COUNT = 15;  // albedo textures the surfaces use (0..MAX_TEXTURES)
PYRO_CONST uint SPEC_WAVEFRONT_STAGE = 16;  // WAVEFRONT_*: the megakernel, or one stage of the wavefront integrator
PYRO_CONST uint WAVEFRONT_NONE = 0;        // the megakernel: each lane runs its paths to the end
PYRO_CONST uint WAVEFRONT_START = 1;       // one lane per pixel: its first camera ray
PYRO_CONST uint WAVEFRONT_TRACK = 2;       // the track queue: free flights up to each path's event
PYRO_CONST uint WAVEFRONT_EVENT = 3;       // the event queue: the event, and the path's next ray
PYRO_CONST uint WAVEFRONT_SIZE_TRACK = 4;  // one lane: the track dispatch's size from its queue
PYRO_CONST uint WAVEFRONT_SIZE_EVENT = 5;  // one lane: the event dispatch's size from its queue
PYRO_CONST uint WAVEFRONT_BEGIN = 6;       // the begin queue: the path's next ray (split event stage)
PYRO_CONST uint WAVEFRONT_SIZE_BEGIN = 7;  // one lane: the begin dispatch's size from its queue
PYRO_CONST uint SPEC_WAVEFRONT_SPLIT = 17;  // the event stage leaves the next ray to the begin stage
// Every emitting grid's temperature is the second channel of its density
// texture (GpuScene::temperature_in_density): one lookup reads both.
PYRO_CONST uint SPEC_TEMPERATURE_IN_DENSITY = 18;
PYRO_CONST uint SPEC_LIGHT_COUNT = 19;  // analytic lights (the scene's `lights`); 0 compiles their code out
PYRO_CONST uint SPEC_AOVS = 20;  // film.aovs: the light layers and first-hit features (docs/compositing.md "AOVs")
PYRO_CONST uint SPEC_SPARSE_GRIDS = 21;  // some grid is a NanoVDB tree (texture_format "sparse"); false compiles that code out
PYRO_CONST uint SPEC_STOCHASTIC_DENSITY = 22;  // free flights read one texel of the density's trilinear footprint (docs/rendering.md "Stochastic density lookups")
PYRO_CONST uint WAVEFRONT_GROUP = 64;      // lanes per workgroup of the queue stages
// 16-byte words of one path's state: a fixed part and a part per medium.
PYRO_CONST uint WAVEFRONT_PATH_WORDS = 22;
PYRO_CONST uint WAVEFRONT_PATH_WORDS_PER_MEDIUM = 2;
PYRO_CONST uint LIGHT_STRATEGY_BSDF = 0;        // BSDF/phase sampling only: no light sampling code
PYRO_CONST uint LIGHT_STRATEGY_MIS = 1;         // both, power heuristic
PYRO_CONST uint LIGHT_STRATEGY_LIGHT_ONLY = 2;  // debug: next-event estimation only
PYRO_CONST uint DEBUG_NONE = 0;
PYRO_CONST uint DEBUG_RATIO_TRACKING = 1;  // camera rays return ratio-tracking transmittance
PYRO_CONST uint DEBUG_DELTA_TRACKING = 2;  // camera rays return delta-tracking transmittance

PYRO_CONST uint SHAPE_SPHERE = 0;
PYRO_CONST uint SHAPE_BOX = 1;
PYRO_CONST uint SHAPE_GRID = 2;  // bounded by its density texture; data in GpuGrid[slot]

PYRO_CONST uint EMIT_NONE = 0;
PYRO_CONST uint EMIT_CONSTANT = 1;     // grid: Le = emission.rgb (× density via sigma_a)
PYRO_CONST uint EMIT_TEMPERATURE = 2;  // grid: Le = scale × blackbody LUT(T(x))

// One medium (96 bytes). Grid media multiply sigma_a and sigma_s by
// density_scale · density(x). Each row is a vec3 and a scalar: 16 bytes in
// std140, std430 and C++ alike (offsets asserted below).
struct GpuMedium {
  vec3 sigma_a;        // absorption coefficient, 1/unit
  uint shape;          // SHAPE_*
  vec3 sigma_s;        // scattering coefficient, 1/unit
  float g;             // Henyey–Greenstein asymmetry
  vec3 emission;       // homogeneous: sigma_a·Le (per unit length); grid: Le or the blackbody scale
  uint emission_mode;  // EMIT_*
  vec3 center;         // sphere
  float radius;        // sphere
  vec3 box_min;        // box
  uint grid_slot;      // grid: its GpuGrid, textures and emission light
  vec3 box_max;        // box
  float line_points;   // homogeneous, with the line estimator: collection points per chord (host/render/LineEstimator.h), else 0
};

// One grid of a grid medium (density, or temperature) as the shaders read
// it: a dense texture's world -> texel map, or a sparse NanoVDB tree's.
// "Texel coordinates" u: texel i's centre is at u = i + 0.5, the sampler
// reads u / dims; the rows map world points to u (index − origin + 0.5:
// OpenVDB values sit at integer index points). The map is affine, so a ray
// keeps its parameter t in texel space.
struct GridChannel {
  vec4 row0;      // u = (dot(row0, p1), dot(row1, p1), dot(row2, p1)), p1 = (p, 1)
  vec4 row1;
  vec4 row2;
  vec3 dims;      // texels
  float unused0;
  // A sparse grid (texture_format "sparse", shaders/sparse.glsl), in the
  // sparse buffer (BINDING_SPARSE): the byte offset of its NanoVDB grid (0:
  // the grid is a dense texture); the index coordinate of texel coordinate 0
  // (index = u + index_origin); and its flat leaf table, which maps a leaf
  // coordinate (index >> 3) − leaf_origin, inside leaf_dims, to the byte
  // offset of that leaf's 512 values.
  vec3 index_origin;
  uint tree;
  ivec3 leaf_origin;
  uint leaf_table;
  uvec3 leaf_dims;
  uint unused1;
};

// A grid medium's two grids, its temperature mapping and blackbody LUT, and
// its majorant grid (288 bytes).
struct GpuGrid {
  GridChannel density;
  GridChannel temperature;   // the temperature texture's own world -> texel map
  float temperature_offset;  // T = (value − temperature_offset) · temperature_scale kelvin
  float temperature_scale;
  float cutoff_k;            // no emission at or below
  float density_scale;
  float lut_scale;  // the blackbody LUT's coordinate s = ln(T)·lut_scale + lut_offset
  float lut_offset;
  float t_min_k;    // the LUT's lower end: no emission below
  // With the line estimator: cell (0,0,0)'s index in the majorant buffer of
  // the line rates (host/render/LineEstimator.h), per unit world length; 0:
  // this grid's emission is collected at its density majorant's collisions.
  uint line_rate_offset;
  uvec3 majorant_res;     // cells
  uint majorant_offset;   // cell (0,0,0)'s index in the majorant buffer
  vec3 majorant_cell;     // cell size in texels
  float majorant_scale;   // max channel of (sigma_a + sigma_s)·density_scale: a cell's value times this is its majorant
};

// Per-render constants (uniform buffer).
struct FrameConstants {
  vec3 camera_position;
  float tan_half_fov;    // tan(fov_y / 2)
  vec3 camera_forward;   // unit
  float aspect;          // width / height
  vec3 camera_right;     // unit = normalize(cross(forward, up))
  float unused0;
  vec3 camera_up;        // unit = cross(right, forward)
  float unused1;
  vec3 background;       // radiance of escaping rays
  float unused2;
  uint width, height;
  uint medium_count;
  uint max_depth;
  uint seed;
  uint frame_index;      // the animation frame (rng_init's stream)
  uint transparent;      // film.transparent: camera rays that escape add no radiance
  uint unused4;
  // Next-event estimation (LightSelection): the probability that it picks the
  // environment (each emissive grid's is its GpuEmissionCdf pick_probability);
  // the probability that a vertex's continuation comes from its own lobe
  // (p_continue_own); light samples per surface vertex (surface_light_samples);
  // 1 when a surface vertex's continuation is collected by a ratio-tracked ray.
  float p_env;
  float p_continue_own;
  uint surface_light_samples;
  uint ratio_tracked_continuation;
};

// Per-pass values (buffer BINDING_PASS, written before each dispatch).
struct PassConstants {
  uint sample_offset;  // index of this pass's first sample per pixel
  uint spp;            // samples per pixel in this pass
  uint row_begin;      // this dispatch's rows: row_begin <= y < row_end. A pass is dispatched in
  uint row_end;        // bands sized to finish well under a second (RenderSession::run_pass)
};

// What one pass reports back (zeroed before every pass). llvmpipe ends every
// loop of an invocation once all loops together have run 65535 iterations
// (Mesa gallivm: one "looplimiter" per function, lp_exec_endloop), so a pass
// with too much work per SIMD group stops early; the host redoes it in
// smaller passes (RenderSession::run_pass).
struct PassStatus {
  uint unfinished_samples;  // summed over pixels
  uint unused0, unused1, unused2;
};

// The wavefront's queues (buffer BINDING_QUEUES): this header, then four
// queues of `capacity` path slots: two track queues (the one being read, the
// one being filled), the event queue and the begin queue. Zeroed before every band.
struct WavefrontQueues {
  uvec4 track_dispatch;  // xyz: vkCmdDispatchIndirect's workgroups for the track stage
  uvec4 event_dispatch;  // xyz: the same for the event stage
  uvec4 begin_dispatch;  // xyz: the same for the begin stage
  uint track_count0;     // paths in track queue 0
  uint track_count1;     // paths in track queue 1
  uint event_count;      // paths in the event queue
  uint track_read;       // the track queue being read (0 or 1)
  uint capacity;         // paths per queue
  uint begin_count;      // paths in the begin queue
  uint unused0, unused1;
};

// Per-pixel accumulation, Kahan-compensated so float32 sums stay accurate over
// thousands of passes (Kahan 1965; `precise` stops the compiler reassociating).
struct AccumTexel {
  vec3 sum;         // Σ L
  float events;     // Σ real events (absorptions + scatterings)
  vec3 sum_c;       // compensation terms of sum
  float events_c;   // and of events
  vec3 sum_sq;      // Σ L²
  float lookups;    // Σ density lookups (plain sum)
  vec3 sum_sq_c;    // compensation terms of sum_sq
  float nonfinite;  // count of non-finite samples (plain sum)
};

// Per-pixel alpha (docs/compositing.md "Alpha"), Kahan-compensated like
// AccumTexel. Its own binding after the AccumTexels in the same buffer: one
// binding of 80 B per pixel would pass lavapipe's 128 MiB storage-buffer
// range below 1920×1080.
struct AlphaTexel {
  float sum;    // Σ α
  float sum_c;  // compensation term of sum
  float sq;     // Σ α²
  float sq_c;
};

// film.aovs (docs/compositing.md "AOVs"): a pixel's sums over its samples
// of the four light layers, which sum to AccumTexel::sum per sample. Plain
// float sums (no Kahan terms: they would take the binding past lavapipe's
// 128 MiB range at 1920×1080). Its own binding after the AlphaTexels.
struct AovLightTexel {
  vec3 emission;    // media emission reaching the camera unscattered
  float unused0;
  vec3 scatter;     // paths whose first vertex scatters in a medium
  float unused1;
  vec3 surface;     // paths whose first vertex is on a surface
  float unused2;
  vec3 background;  // background, environment, sun discs, sphere lights seen directly
  float unused3;
};

// film.aovs: sums of the camera ray's first-event features over the samples
// that have one (hits counts them), and the pixel's denoiser guide (written
// once, by the first pass: accumulation.glsl add_pixel_guide; guide.glsl: the
// media's emission along the camera ray, and its alpha, by a deterministic
// ray march).
struct AovFeatureTexel {
  vec3 albedo;
  float depth;
  vec3 normal;
  float hits;
  vec3 guide;
  float guide_alpha;
};

#ifndef __cplusplus
// A grid's stored temperature value in kelvin, T = (value − offset)·scale: the
// shaders' one copy of the mapping (the host's, in double, is
// TemperatureMapping::kelvin, host/volume/VolumeOptions.h).
float grid_kelvin(float value, float temperature_offset, float temperature_scale) {
  return (value - temperature_offset) * temperature_scale;
}
#endif

#ifdef __cplusplus
// Every field where std140/std430 put it (a vec3 ends 4 bytes before the next 16).
static_assert(sizeof(GpuMedium) == 96);
PYRO_OFFSET(GpuMedium, shape, 12); PYRO_OFFSET(GpuMedium, sigma_s, 16); PYRO_OFFSET(GpuMedium, g, 28);
PYRO_OFFSET(GpuMedium, emission, 32); PYRO_OFFSET(GpuMedium, emission_mode, 44); PYRO_OFFSET(GpuMedium, center, 48);
PYRO_OFFSET(GpuMedium, radius, 60); PYRO_OFFSET(GpuMedium, box_min, 64); PYRO_OFFSET(GpuMedium, grid_slot, 76);
PYRO_OFFSET(GpuMedium, box_max, 80); PYRO_OFFSET(GpuMedium, line_points, 92);
static_assert(sizeof(GridChannel) == 112);
PYRO_OFFSET(GridChannel, row1, 16); PYRO_OFFSET(GridChannel, row2, 32); PYRO_OFFSET(GridChannel, dims, 48);
PYRO_OFFSET(GridChannel, unused0, 60); PYRO_OFFSET(GridChannel, index_origin, 64); PYRO_OFFSET(GridChannel, tree, 76);
PYRO_OFFSET(GridChannel, leaf_origin, 80); PYRO_OFFSET(GridChannel, leaf_table, 92);
PYRO_OFFSET(GridChannel, leaf_dims, 96); PYRO_OFFSET(GridChannel, unused1, 108);
static_assert(sizeof(GpuGrid) == 288);
PYRO_OFFSET(GpuGrid, temperature, 112); PYRO_OFFSET(GpuGrid, temperature_offset, 224);
PYRO_OFFSET(GpuGrid, temperature_scale, 228); PYRO_OFFSET(GpuGrid, cutoff_k, 232); PYRO_OFFSET(GpuGrid, density_scale, 236);
PYRO_OFFSET(GpuGrid, lut_scale, 240); PYRO_OFFSET(GpuGrid, lut_offset, 244); PYRO_OFFSET(GpuGrid, t_min_k, 248);
PYRO_OFFSET(GpuGrid, line_rate_offset, 252); PYRO_OFFSET(GpuGrid, majorant_res, 256);
PYRO_OFFSET(GpuGrid, majorant_offset, 268); PYRO_OFFSET(GpuGrid, majorant_cell, 272);
PYRO_OFFSET(GpuGrid, majorant_scale, 284);
static_assert(sizeof(FrameConstants) == 128);
PYRO_OFFSET(FrameConstants, tan_half_fov, 12); PYRO_OFFSET(FrameConstants, camera_forward, 16);
PYRO_OFFSET(FrameConstants, aspect, 28); PYRO_OFFSET(FrameConstants, camera_right, 32);
PYRO_OFFSET(FrameConstants, unused0, 44); PYRO_OFFSET(FrameConstants, camera_up, 48);
PYRO_OFFSET(FrameConstants, unused1, 60); PYRO_OFFSET(FrameConstants, background, 64);
PYRO_OFFSET(FrameConstants, unused2, 76); PYRO_OFFSET(FrameConstants, width, 80);
PYRO_OFFSET(FrameConstants, height, 84); PYRO_OFFSET(FrameConstants, medium_count, 88);
PYRO_OFFSET(FrameConstants, max_depth, 92); PYRO_OFFSET(FrameConstants, seed, 96);
PYRO_OFFSET(FrameConstants, frame_index, 100); PYRO_OFFSET(FrameConstants, transparent, 104);
PYRO_OFFSET(FrameConstants, unused4, 108); PYRO_OFFSET(FrameConstants, p_env, 112);
PYRO_OFFSET(FrameConstants, p_continue_own, 116); PYRO_OFFSET(FrameConstants, surface_light_samples, 120);
PYRO_OFFSET(FrameConstants, ratio_tracked_continuation, 124);
static_assert(sizeof(PassConstants) == 16);
PYRO_OFFSET(PassConstants, spp, 4); PYRO_OFFSET(PassConstants, row_begin, 8); PYRO_OFFSET(PassConstants, row_end, 12);
static_assert(sizeof(PassStatus) == 16);
PYRO_OFFSET(PassStatus, unused0, 4); PYRO_OFFSET(PassStatus, unused1, 8); PYRO_OFFSET(PassStatus, unused2, 12);
static_assert(sizeof(WavefrontQueues) == 80);
PYRO_OFFSET(WavefrontQueues, event_dispatch, 16); PYRO_OFFSET(WavefrontQueues, begin_dispatch, 32);
PYRO_OFFSET(WavefrontQueues, track_count0, 48); PYRO_OFFSET(WavefrontQueues, track_count1, 52);
PYRO_OFFSET(WavefrontQueues, event_count, 56); PYRO_OFFSET(WavefrontQueues, track_read, 60);
PYRO_OFFSET(WavefrontQueues, capacity, 64); PYRO_OFFSET(WavefrontQueues, begin_count, 68);
PYRO_OFFSET(WavefrontQueues, unused0, 72); PYRO_OFFSET(WavefrontQueues, unused1, 76);
static_assert(sizeof(AccumTexel) == 64);
PYRO_OFFSET(AccumTexel, events, 12); PYRO_OFFSET(AccumTexel, sum_c, 16); PYRO_OFFSET(AccumTexel, events_c, 28);
PYRO_OFFSET(AccumTexel, sum_sq, 32); PYRO_OFFSET(AccumTexel, lookups, 44); PYRO_OFFSET(AccumTexel, sum_sq_c, 48);
PYRO_OFFSET(AccumTexel, nonfinite, 60);
static_assert(sizeof(AlphaTexel) == 16);
PYRO_OFFSET(AlphaTexel, sum_c, 4); PYRO_OFFSET(AlphaTexel, sq, 8); PYRO_OFFSET(AlphaTexel, sq_c, 12);
static_assert(sizeof(AovLightTexel) == 64);
PYRO_OFFSET(AovLightTexel, scatter, 16); PYRO_OFFSET(AovLightTexel, surface, 32); PYRO_OFFSET(AovLightTexel, background, 48);
static_assert(sizeof(AovFeatureTexel) == 48);
PYRO_OFFSET(AovFeatureTexel, depth, 12); PYRO_OFFSET(AovFeatureTexel, normal, 16); PYRO_OFFSET(AovFeatureTexel, hits, 28);
PYRO_OFFSET(AovFeatureTexel, guide, 32); PYRO_OFFSET(AovFeatureTexel, guide_alpha, 44);
}  // namespace pyrolume::gpu
#endif
#endif
