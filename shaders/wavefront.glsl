// The wavefront integrator's stages (included by render.comp after the path
// code; docs/benchmarks.md "A wavefront prototype"). The megakernel runs every
// path of a pixel in one lane, and llvmpipe runs all of path_step's code, the
// vertex and light code included, for every lane on every pass. Here each
// path's state lives in a texel buffer between stages, and each stage is its
// own pipeline (SPEC_WAVEFRONT_STAGE) holding only its own code:
//
//   START  one lane per pixel: the first camera ray, queued for TRACK;
//   TRACK  the track queue: free flights (path_track) until half the SIMD
//          group has its event; paths with one go to the event queue, the
//          others back to the next track queue;
//   EVENT  the event queue: the event (path_event), then the path's next ray
//          (settle: the pixel's next camera ray, path_begin), queued for
//          TRACK; a pixel whose samples are all done adds its pass. With
//          WAVEFRONT_SPLIT the next ray is left to
//   BEGIN  the begin queue: settle, queued for TRACK.
//
// Queues are filled by atomic counters; the SIZE_* stages (one lane) turn a
// count into a vkCmdDispatchIndirect size (Laine et al. 2013, "Megakernels
// considered harmful"). Every path runs the megakernel's code on the same
// random numbers in the same order, so the image is bit-identical to the
// megakernel's. On lavapipe it is slower: moving the state costs a stage
// about what its work does.

layout(constant_id = SPEC_WAVEFRONT_STAGE) const uint WAVEFRONT_STAGE = WAVEFRONT_NONE;
layout(set = 0, binding = BINDING_PATHS, rgba32ui) uniform uimageBuffer path_vec;
layout(std430, set = 0, binding = BINDING_QUEUES) buffer QueueBlock {
  WavefrontQueues queues;
  uint queue_slots[];  // track queues 0 and 1, the event queue, the begin queue: queues.capacity slots each
};

const uint PATH_STRIDE = WAVEFRONT_PATH_WORDS + MEDIA_N * WAVEFRONT_PATH_WORDS_PER_MEDIUM;
const uint EVENT_QUEUE = 2u, BEGIN_QUEUE = 3u;
layout(constant_id = SPEC_WAVEFRONT_SPLIT) const bool WAVEFRONT_SPLIT = false;

// What a path needs besides PathState between stages: its pixel's sample
// index and pass sums, its random stream, and the event TRACK found.
struct SlotState {
  uint rng, k;
  // 0: the ray is ready for free flights; 1: path_begin must run again
  // first; 2: the same, the sample having ended (settle's loop ran out).
  uint pending;
  uint event;
  Collision c;
  vec3 sum, sum_c, sq, sq_c;
  vec2 alpha;  // Σα, Σα²
  float nonfinite;
  PathStats stats;
};

// One layout for loads and stores, in 16-byte words (llvmpipe gathers each
// lane's load separately: four floats cost what one does). io(store, at, u)
// reads word `at` into u or writes u there; each group packs its fields into
// u before and unpacks them after, so one list serves both directions.
void io(bool store, uint at, inout uvec4 u) {
  if (store) imageStore(path_vec, int(at), u);
  else u = imageLoad(path_vec, int(at));
}
void io_v3f(bool store, uint at, inout vec3 a, inout float b) {
  uvec4 u = uvec4(floatBitsToUint(a), floatBitsToUint(b));
  io(store, at, u);
  a = uintBitsToFloat(u.xyz);
  b = uintBitsToFloat(u.w);
}
void io_v3u(bool store, uint at, inout vec3 a, inout uint b) {
  uvec4 u = uvec4(floatBitsToUint(a), b);
  io(store, at, u);
  a = uintBitsToFloat(u.xyz);
  b = u.w;
}
void io_v3b(bool store, uint at, inout vec3 a, inout bool b) {
  uint u = b ? 1u : 0u;
  io_v3u(store, at, a, u);
  b = u != 0u;
}
uint b2u(bool b) { return b ? 1u : 0u; }

// Path slot `slot`'s state. TRACK moves only what free flights read and
// write (everything = false): words 0–8 and each medium's first word.
void path_io(bool store, bool everything, uint slot, inout PathState p, inout SlotState s, inout vec2 span[MEDIA_N],
             inout MediumPoint mp) {
  const uint base = slot * PATH_STRIDE;
  io_v3f(store, base + 0u, p.o, p.t);
  io_v3f(store, base + 1u, p.d, p.pdf_dir);
  io_v3f(store, base + 2u, p.w, p.p_light);
  io_v3f(store, base + 3u, p.L, p.hit.t);
  uvec4 u = uvec4(b2u(p.has_hit), b2u(p.light_ray), floatBitsToUint(p.light_T), b2u(p.skip_segment));
  io(store, base + 4u, u);
  p.has_hit = u.x != 0u;
  p.light_ray = u.y != 0u;
  p.light_T = uintBitsToFloat(u.z);
  p.skip_segment = u.w != 0u;
  u = uvec4(s.rng, floatBitsToUint(s.stats.events), floatBitsToUint(s.stats.lookups), s.pending);
  io(store, base + 5u, u);
  s.rng = u.x;
  s.stats = PathStats(uintBitsToFloat(u.y), uintBitsToFloat(u.z));
  s.pending = u.w;
  io_v3u(store, base + 6u, s.c.x, s.event);
  io_v3f(store, base + 7u, s.c.sigma_s, s.c.sigma_maj);
  u = uvec4(floatBitsToUint(s.c.p_a), floatBitsToUint(s.c.p_s), floatBitsToUint(p.alpha), 0u);
  io(store, base + 8u, u);
  s.c.p_a = uintBitsToFloat(u.x);
  s.c.p_s = uintBitsToFloat(u.y);
  p.alpha = uintBitsToFloat(u.z);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    const uint m = base + WAVEFRONT_PATH_WORDS + i * WAVEFRONT_PATH_WORDS_PER_MEDIUM;
    vec4 f = vec4(span[i], mp.rho[i], mp.temperature_value[i]);
    u = floatBitsToUint(f);
    io(store, m, u);
    f = uintBitsToFloat(u);
    span[i] = f.xy;
    mp.rho[i] = f.z;
    mp.temperature_value[i] = f.w;
    if (everything) io_v3f(store, m + 1u, p.vertex_share[i], p.vertex_q[i]);
  }
  if (!everything) return;
  u = uvec4(p.depth, b2u(p.fresh), floatBitsToUint(p.survival), p.hit.kind);
  io(store, base + 9u, u);
  p.depth = u.x;
  p.fresh = u.y != 0u;
  p.survival = uintBitsToFloat(u.z);
  p.hit.kind = u.w;
  u = uvec4(p.hit.primitive, floatBitsToUint(p.hit.bary), p.continuation_ray);
  io(store, base + 10u, u);
  p.hit.primitive = u.x;
  p.hit.bary = uintBitsToFloat(u.yz);
  p.continuation_ray = u.w;
  io_v3f(store, base + 11u, p.next_o, p.next_pdf_dir);
  io_v3f(store, base + 12u, p.next_d, p.next_p_light);
  io_v3b(store, base + 13u, p.next_w, p.next_ends);
  io_v3u(store, base + 14u, p.vertex_wa, p.lights_left);
  io_v3b(store, base + 15u, p.vertex_n, p.light_pending);
  u = floatBitsToUint(p.vertex_norm);
  io(store, base + 16u, u);
  p.vertex_norm = uintBitsToFloat(u);
  io_v3b(store, base + 17u, p.vertex_d_in, p.vertex_medium);
  io_v3u(store, base + 18u, s.sum, s.k);
  io_v3f(store, base + 19u, s.sum_c, s.nonfinite);
  io_v3f(store, base + 20u, s.sq, s.alpha.x);
  io_v3f(store, base + 21u, s.sq_c, s.alpha.y);
}

// Append slot to queue q (0, 1: track queues; EVENT_QUEUE; BEGIN_QUEUE).
void enqueue(uint q, uint slot) {
  uint j;
  if (q == 0u) j = atomicAdd(queues.track_count0, 1u);
  else if (q == 1u) j = atomicAdd(queues.track_count1, 1u);
  else if (q == EVENT_QUEUE) j = atomicAdd(queues.event_count, 1u);
  else j = atomicAdd(queues.begin_count, 1u);
  queue_slots[q * queues.capacity + j] = slot;
}

uvec2 slot_pixel(uint slot) {
  const uint width = frame.width;
  return uvec2(slot % width, slot / width + pass_constants.row_begin);
}

// Bring the path to its next ray that needs free flights: the sample's end
// (ended) adds it to the pass and starts the pixel's next camera ray; then
// path_begin. Returns false once the pixel's samples of this pass are all
// done. A bounded loop (llvmpipe runs a loop's body for the whole SIMD group
// until its last lane leaves): what is left over is marked pending.
bool settle(uvec2 pixel, inout PathState p, inout SlotState s, inout vec2 span[MEDIA_N], bool ended) {
  const uint last = pass_constants.sample_offset + pass_constants.spp;
  for (uint n = 0u; n < 4u; ++n) {
    if (ended) {
      add_sample(p.L, p.alpha, s.sum, s.sum_c, s.sq, s.sq_c, s.alpha, s.nonfinite);
      if (++s.k >= last) return false;
      camera_path(pixel, s.k, s.rng, p);
    }
    const int begun = path_begin(p, span, s.rng);
    if (begun == RAY_READY) {
      s.pending = 0u;
      return true;
    }
    ended = begun == PATH_ENDED;
  }
  s.pending = ended ? 2u : 1u;
  return true;
}

void finish_slot(uint slot, SlotState s) {
  const uvec2 pixel = slot_pixel(slot);
  add_pass(pixel.y * frame.width + pixel.x, s.sum, s.sum_c, s.sq, s.sq_c, s.alpha, s.stats, s.nonfinite);
}

void wavefront_main() {
  if ((WAVEFRONT_STAGE == WAVEFRONT_SIZE_TRACK || WAVEFRONT_STAGE == WAVEFRONT_SIZE_EVENT ||
       WAVEFRONT_STAGE == WAVEFRONT_SIZE_BEGIN) &&
      gl_LocalInvocationIndex != 0u)
    return;  // one lane of the one workgroup
  if (WAVEFRONT_STAGE == WAVEFRONT_SIZE_TRACK) {
    // The track queue filled last becomes the one read; the other and the
    // event queue start empty.
    const uint read = queues.track_read ^ 1u;
    queues.track_read = read;
    const uint n = read == 0u ? queues.track_count0 : queues.track_count1;
    queues.track_dispatch = uvec4((n + WAVEFRONT_GROUP - 1u) / WAVEFRONT_GROUP, 1u, 1u, 0u);
    if (read == 0u) queues.track_count1 = 0u;
    else queues.track_count0 = 0u;
    queues.event_count = 0u;
    queues.begin_count = 0u;
    return;
  }
  if (WAVEFRONT_STAGE == WAVEFRONT_SIZE_EVENT) {
    queues.event_dispatch = uvec4((queues.event_count + WAVEFRONT_GROUP - 1u) / WAVEFRONT_GROUP, 1u, 1u, 0u);
    return;
  }
  if (WAVEFRONT_STAGE == WAVEFRONT_SIZE_BEGIN) {
    queues.begin_dispatch = uvec4((queues.begin_count + WAVEFRONT_GROUP - 1u) / WAVEFRONT_GROUP, 1u, 1u, 0u);
    return;
  }
  PathState p;
  SlotState s;
  vec2 span[MEDIA_N];
  MediumPoint mp;  // per medium rho and temperature_value travel (path_io); sigma_a, sigma_s do not
  const uint read = queues.track_read, fill = read ^ 1u;
  if (WAVEFRONT_STAGE == WAVEFRONT_START) {
    const uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, pass_constants.row_begin);
    if (pixel.x >= frame.width || pixel.y >= min(frame.height, pass_constants.row_end)) return;
    const uint slot = (pixel.y - pass_constants.row_begin) * frame.width + pixel.x;
    s.k = pass_constants.sample_offset;
    s.sum = s.sum_c = s.sq = s.sq_c = vec3(0.0);
    s.alpha = vec2(0.0);
    s.nonfinite = 0.0;
    s.stats = PathStats(0.0, 0.0);
    s.event = EVENT_NONE;
    s.c = Collision(vec3(0.0), vec3(0.0), 0.0, 0.0, 0.0, vec3(0.0));
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) mp.rho[i] = mp.temperature_value[i] = 0.0;
    camera_path(pixel, s.k, s.rng, p);
    if (!settle(pixel, p, s, span, false)) {
      finish_slot(slot, s);
      return;
    }
    path_io(true, true, slot, p, s, span, mp);
    enqueue(fill, slot);
    return;
  }
  const uint j = gl_WorkGroupID.x * WAVEFRONT_GROUP + gl_LocalInvocationIndex;
  if (WAVEFRONT_STAGE == WAVEFRONT_TRACK) {
    if (j >= (read == 0u ? queues.track_count0 : queues.track_count1)) return;
    const uint slot = queue_slots[read * queues.capacity + j];
    path_io(false, false, slot, p, s, span, mp);
    if (s.pending == 0u) s.event = path_track(p, span, s.rng, s.stats, s.c, mp);
    path_io(true, false, slot, p, s, span, mp);
    enqueue(s.pending != 0u ? (WAVEFRONT_SPLIT ? BEGIN_QUEUE : EVENT_QUEUE) : s.event != EVENT_NONE ? EVENT_QUEUE : fill,
            slot);
    return;
  }
  if (WAVEFRONT_STAGE == WAVEFRONT_EVENT) {
    if (j >= queues.event_count) return;
    const uint slot = queue_slots[EVENT_QUEUE * queues.capacity + j];
    path_io(false, true, slot, p, s, span, mp);
    const bool ended = s.pending != 0u ? s.pending == 2u
                                       : path_event(p, span, s.event, s.c, mp, s.rng, s.stats);
    if (WAVEFRONT_SPLIT) {
      s.pending = ended ? 2u : 1u;
      path_io(true, true, slot, p, s, span, mp);
      enqueue(BEGIN_QUEUE, slot);
      return;
    }
    if (!settle(slot_pixel(slot), p, s, span, ended)) {
      finish_slot(slot, s);
      return;
    }
    path_io(true, true, slot, p, s, span, mp);
    enqueue(fill, slot);
  }
  if (WAVEFRONT_STAGE == WAVEFRONT_BEGIN) {
    if (j >= queues.begin_count) return;
    const uint slot = queue_slots[BEGIN_QUEUE * queues.capacity + j];
    path_io(false, true, slot, p, s, span, mp);
    if (!settle(slot_pixel(slot), p, s, span, s.pending == 2u)) {
      finish_slot(slot, s);
      return;
    }
    path_io(true, true, slot, p, s, span, mp);
    enqueue(fill, slot);
  }
}
