// Structs and constants shared by the host (C++) and the shaders (GLSL): the one
// source of truth for data that crosses the boundary. Written in the common subset
// of both languages; only vec4/uvec4 members, so std140 and std430 agree and no
// vec3 padding can drift. The C++ side static_asserts every size below.
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
PYRO_CONST uint BINDING_MAJORANTS = 4; // readonly buffer float[]: every grid's majorant cells
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
PYRO_CONST uint BINDING_EMISSION_CLUSTERS = 22; // readonly buffer GpuEmissionCluster[]: their clusters
PYRO_CONST uint BINDING_PASS_STATUS = 21;      // buffer PassStatus: what the pass could not finish
PYRO_CONST uint BINDING_PATHS = 23;    // uimageBuffer (rgba32ui): the wavefront's path states (shaders/wavefront.glsl path_io)
PYRO_CONST uint BINDING_LIGHTS = 25;    // readonly buffer GpuLight[]: the scene's analytic lights (shared/light_types.h)
PYRO_CONST uint BINDING_QUEUES = 24;   // buffer WavefrontQueues, then its queues of path slots

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
PYRO_CONST uint SPEC_HAS_ANALYTIC_MEDIA = 14;  // a sphere or box medium (else every medium is a grid)
PYRO_CONST uint SPEC_ALBEDO_TEXTURE_COUNT = 15;  // albedo textures the surfaces use (0..MAX_TEXTURES)
PYRO_CONST uint SPEC_EARLY_EVENT_EXIT = 13;  // free flights leave once half the SIMD group has its event (render.comp path_track)
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
// density_scale · density(x).
struct GpuMedium {
  vec4 sigma_a;   // rgb: absorption coefficient, 1/unit; w: shape (SHAPE_*)
  vec4 sigma_s;   // rgb: scattering coefficient, 1/unit; w: Henyey–Greenstein g
  vec4 emission;  // homogeneous: rgb sigma_a·Le (per unit length); grid: rgb Le or blackbody scale; w: EMIT_*
  vec4 bounds0;   // sphere: xyz centre, w radius; box: xyz min; grid: x = slot
  vec4 bounds1;   // box: xyz max
  vec4 reserved;
};

// A grid medium's textures and majorant grid (192 bytes). "Texel coordinates"
// u: texel i's centre is at u = i + 0.5, the sampler reads u / dims; the rows map
// world points to u (index − origin + 0.5: OpenVDB values sit at integer index
// points). The map is affine, so a ray keeps its parameter t in texel space.
struct GpuGrid {
  vec4 density_row0;      // u = (dot(row0, p1), dot(row1, p1), dot(row2, p1)), p1 = (p, 1)
  vec4 density_row1;
  vec4 density_row2;
  vec4 density_dims;      // xyz: texels; w: density_scale
  vec4 temperature_row0;  // the temperature texture's own world -> texel map
  vec4 temperature_row1;
  vec4 temperature_row2;
  vec4 temperature_dims;  // xyz: texels; w: unused
  vec4 temperature_map;   // T = (value - x) · y kelvin; z: cutoff_k; w: unused
  vec4 blackbody_lut;     // s = ln(T)·x + y; z: t_min_k (no emission below); w: unused
  uvec4 majorant_res;     // xyz: cells; w: offset of cell (0,0,0) in the majorant buffer
  vec4 majorant_cell;     // xyz: cell size in texels; w: max channel of (sigma_a + sigma_s)·density_scale
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
  vec4 lights;           // x: probability that next-event estimation picks the environment
                         // (each emissive grid's is its GpuEmissionCdf measure.w); y: probability
                         // that a vertex's continuation comes from its own lobe (LightSelection
                         // p_continue_own); z: next-event samples per surface vertex
                         // (LightSelection surface_light_samples); w: 1 when a surface vertex's
                         // continuation is collected by a ratio-tracked ray (ratio_tracked_continuation)
};

// Per-pass values (push constants).
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
  uvec4 counts;  // x: samples not finished (summed over pixels); yzw: 0
};

// The wavefront's queues (buffer BINDING_QUEUES): this header, then four
// queues of `capacity` path slots: two track queues (the one being read, the
// one being filled), the event queue and the begin queue. Zeroed before every band.
struct WavefrontQueues {
  uvec4 track_dispatch;  // xyz: vkCmdDispatchIndirect's workgroups for the track stage
  uvec4 event_dispatch;  // xyz: the same for the event stage
  uvec4 begin_dispatch;  // xyz: the same for the begin stage
  uvec4 counts;          // x, y: paths in track queue 0, 1; z: in the event queue; w: the track queue being read
  uvec4 sizes;           // x: capacity (paths per queue); y: paths in the begin queue; zw: unused
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
static_assert(sizeof(GpuGrid) == 192);
static_assert(sizeof(FrameConstants) == 128);
static_assert(offsetof(FrameConstants, image) == 80);
static_assert(sizeof(PassConstants) == 16);
static_assert(sizeof(AccumTexel) == 64);
static_assert(sizeof(PassStatus) == 16);
static_assert(sizeof(WavefrontQueues) == 80);
}  // namespace pyrolume::gpu
#endif
#endif
