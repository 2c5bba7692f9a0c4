// One path's state between tracking steps and its transitions between rays
// (camera ray, light rays, continuation): render.comp's state machine. Paths
// are regenerated within a lane, so the state lives outside any per-path loop.

// PathState.continuation_ray (docs/mis.md "Ratio-tracked continuation"):
// the vertex's continuation is an ordinary ray (PLAIN); a light ray along it
// is still to come (PENDING); that light ray is running, so the continuation
// then collects nothing on its first segment (TRACKING, skip_segment).
const uint CONTINUATION_PLAIN = 0u;
const uint CONTINUATION_PENDING = 1u;
const uint CONTINUATION_TRACKING = 2u;

struct PathState {
  vec3 o, d;   // current ray
  vec3 w;      // path weight (per channel)
  vec3 L;      // radiance gathered so far
  // This sample's alpha (docs/compositing.md "Alpha"): 1 unless the camera ray
  // escapes, then 1 − avg(w), w its delta-tracking weight (E[w·escaped] = T).
  float alpha;
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
  // The path's phase, as flags (one uint was slower: docs/benchmarks.md "The
  // path's phase as one value"): a camera or continuation ray (!light_ray);
  // a light ray (light_ray, continuation_ray != CONTINUATION_TRACKING); the
  // ratio-tracked continuation's first segment (light_ray,
  // CONTINUATION_TRACKING); the vertex's next light ray still to draw
  // (light_pending).
  bool light_ray;
  float light_T;  // a light ray's ratio-tracking transmittance (max channel) since its last roulette
  // Ratio-tracked continuation (docs/mis.md): CONTINUATION_* below.
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
  // film.aovs (docs/compositing.md "AOVs"; only with AOVS): L_direct, what
  // the camera ray sees of the background and sphere lights; L_first, L when
  // the path made its first vertex (first_vertex: AOV_VERTEX_*). Then the
  // camera ray's first event's features (has_feature: it had one).
  vec3 L_direct, L_first;
  uint first_vertex;
  bool has_feature;
  vec3 feature_albedo, feature_normal;
  float feature_depth;
};

const uint AOV_VERTEX_NONE = 0u, AOV_VERTEX_MEDIUM = 1u, AOV_VERTEX_SURFACE = 2u;

// film.aovs: the camera ray's first event (depth 0) sets the features.
void set_features(inout PathState p, vec3 albedo, vec3 normal, vec3 x) {
  if (!AOVS || p.depth != 0u || p.has_feature) return;
  p.has_feature = true;
  p.feature_albedo = albedo;
  p.feature_normal = normal;
  p.feature_depth = distance(x, frame.camera_position);
}

// film.aovs: the single-scattering albedo σs/σt of a real collision.
vec3 collision_albedo(vec3 sigma_a, vec3 sigma_s) {
  const vec3 sigma_t = sigma_a + sigma_s;
  return mix(vec3(0.0), sigma_s / max(sigma_t, vec3(1e-30)), greaterThan(sigma_t, vec3(0.0)));
}

// The ray leaves the scene: add what it sees, MIS-weighted. A light ray
// toward a delta distant light has reached it.
void escape(inout PathState p) {
  if (LIGHT_COUNT > 0u && p.delta_light < LIGHT_COUNT) {
    if (analytic_lights[p.delta_light].kind == LIGHT_DISTANT) p.L += p.w;
    return;
  }
  if (p.depth == 0u) {  // the camera ray (light rays start at vertices, after depth counts them)
    p.alpha = 1.0 - avg3(p.w);
    if (frame.transparent != 0u) return;  // the plate shows there: no background
  }
  if (p.skip_segment) return;
  const vec3 seen = unidirectional_weight(p.pdf_dir, p.p_light) * p.w * escaped_radiance(p.d);
  p.L += seen;
  if (AOVS && p.depth == 0u) p.L_direct = seen;
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

// The vertex's light rays are done: the continuation starts (true: the path
// has ended). With a ratio-tracked continuation, first one more light ray
// along the continuation's direction, with its weight and MIS weight: it
// collects the continuation's first segment, which the path then skips.
bool hand_over(inout PathState p) {
  if (p.next_ends) {
    p.light_ray = false;
    return true;
  }
  if (p.continuation_ray == CONTINUATION_PENDING) {
    p.continuation_ray = CONTINUATION_TRACKING;
    p.w = p.next_w * unidirectional_weight(p.next_pdf_dir, p.next_p_light);
    new_ray(p, p.next_o, p.next_d, 0.0, 0.0);
    return false;
  }
  p.light_ray = false;
  p.w = p.next_w;
  new_ray(p, p.next_o, p.next_d, p.next_pdf_dir, p.next_p_light);
  p.skip_segment = p.continuation_ray == CONTINUATION_TRACKING;
  p.continuation_ray = CONTINUATION_PLAIN;
  return false;
}

// The current ray ends. A light ray hands over to the vertex's next light ray
// or to the continuation it sampled; returns true when the path has ended. The
// next light ray is drawn by path_begin (light_pending), in one place
// (docs/rendering.md "llvmpipe workarounds": one copy of the light code).
bool ray_ends(inout PathState p) {
  if (!NEE || !p.light_ray) return true;
  if (p.lights_left > 0u) {
    p.light_pending = true;
    return false;
  }
  return hand_over(p);
}
