// One path, step by step: its next ray (path_begin), free flights
// (tracking.glsl), the event (path_event); camera_path starts it.
// path_begin's answers: the ray is ready for free flights, or it ended before
// any (the path goes on with its next ray, or has ended).
const int RAY_READY = -1, RAY_ENDED = 0, PATH_ENDED = 1;

// Sphere lights that a fresh ray meets before its surface hit, and where a
// light ray toward a point or spot light reaches it: a hit of kind
// SURFACE_HIT_LIGHT (primitive: the light).
void lights_on_ray(inout PathState p) {
  float t = p.has_hit ? p.hit.t : INF;
  uint light = intersect_sphere_lights(p.o, p.d, t);
  if (p.delta_light < LIGHT_COUNT && analytic_lights[p.delta_light].kind != LIGHT_DISTANT) {
    const float r = length(analytic_lights[p.delta_light].position - p.o);
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


// What a ray segment's event does (path_step's end); true when the path has ended.
bool path_event(inout PathState p, vec2 span[MEDIA_N], uint event, Collision c, MediumPoint mp, inout uint rng,
                inout PathStats stats) {
  const vec3 x = c.x, sigma_s = c.sigma_s;
  const float sigma_maj = c.sigma_maj, p_a = c.p_a, p_s = c.p_s;
  if (event == EVENT_ESCAPE) {
    escape(p);
    return ray_ends(p);
  }
  if (LIGHT_COUNT > 0u && event == EVENT_SURFACE && p.hit.kind == SURFACE_HIT_LIGHT) {
    // A delta light ray arrives (its weight holds f·I/(r²·P)); any other ray
    // sees the sphere light's radiance, MIS-weighted, and ends: it is opaque.
    if (p.hit.primitive == p.delta_light) {
      p.L += p.w;
    } else if (!p.skip_segment) {
      const vec3 x_light = p.o + p.hit.t * p.d;
      const vec3 seen = unidirectional_weight(p.pdf_dir, p.p_light) * p.w *
                        sphere_light_radiance(analytic_lights[p.hit.primitive], x_light, p.d);
      p.L += seen;
      if (AOVS && p.depth == 0u) {
        p.L_direct = seen;
        set_features(p, vec3(0.0), normalize(x_light - analytic_lights[p.hit.primitive].position), x_light);
      }
    }
    return ray_ends(p);
  }
  if (event == EVENT_END || (event == EVENT_SURFACE && NEE && p.light_ray)) return ray_ends(p);
  const bool surface = HAS_SURFACES && event == EVENT_SURFACE;
  if (!surface) {
    stats.events += 1.0;
    set_features(p, collision_albedo(c.sigma_a, sigma_s), vec3(0.0), x);
    // The absorption estimator collects sigma_a·Le / (sigma_maj·P_a) where the
    // path is absorbed. A medium's real collision scatters whenever it can
    // (implicit capture, path_track): there it collects what an absorption
    // would have, as its expected value sigma_a·Le / (sigma_maj·(P_a + P_s)),
    // p_s being P_a + P_s. Every real collision of the path adds its share,
    // each weighted by the scattering that led to it, instead of one
    // all-or-nothing sample where the path happens to be absorbed. One copy
    // of the emission lookup serves both events (docs/rendering.md "llvmpipe
    // workarounds": every branch runs).
    if (HAS_EMISSION && !COLLISION_ESTIMATOR) {
      // rho is the free flight's (stochastic) estimate, as in P_a and P_s:
      // sigma_a(rho)/(sigma_maj·P) keeps its expectation; the temperature is
      // the trilinear value (media.glsl event_temperatures).
      event_temperatures(x, p.t, span, mp);
      p.L += p.w * emission_at(x, p.t, span, mp) /
             (sigma_maj * (event == EVENT_ABSORB ? p_a : p_s));
    }
    if (event == EVENT_ABSORB) return ray_ends(p);
  }
  return scatter_vertex(p, surface, x, sigma_s, sigma_maj, p_s, mp.rho, rng, stats);
}

// One step of delta tracking along one path: its next ray if needed, free
// flights, the event. Returns true when the path has ended (p.L is then final).
bool path_step(inout PathState p, inout vec2 span[MEDIA_N], inout uint rng, inout PathStats stats) {
  const int begun = path_begin(p, span, rng);
  if (begun != RAY_READY) return begun == PATH_ENDED;
  Collision c;
  MediumPoint mp;
  const uint event = path_track(p, span, rng, stats, c, mp);
  if (event == EVENT_NONE) return false;  // EARLY_EVENT_EXIT: still in free flight
  return path_event(p, span, event, c, mp, rng, stats);
}

// Start p as a camera ray through pixel `pixel` for sample `k`, with that
// sample's random stream (p is filled in place: PathState holds arrays sized
// by a specialisation constant, which GLSL cannot copy).
void camera_path(uvec2 pixel, uint k, out uint rng, inout PathState p) {
  uint width = frame.width, height = frame.height;
  const uint pixel_index = pixel.y * width + pixel.x;
  rng = rng_init(frame.seed, frame.frame_index, pixel_index, k);
  // Box filter: a point inside the pixel, uniform for each sample but
  // stratified across the pixel's samples; pixel (0,0) is top-left.
  vec2 jitter = film_jitter(frame.seed, frame.frame_index, pixel_index, k);
  p.o = frame.camera_position;
  p.d = camera_direction(pixel, jitter);
  p.w = vec3(1.0);
  p.L = vec3(0.0);
  p.alpha = 1.0;
  p.t = 0.0;
  p.depth = 0u;
  p.fresh = true;
  p.has_hit = false;
  p.pdf_dir = 0.0;
  p.p_light = 0.0;
  p.survival = 1.0;
  p.light_ray = false;
  p.light_T = 1.0;
  p.continuation_ray = CONTINUATION_PLAIN;
  p.skip_segment = false;
  p.next_ends = true;
  p.next_o = p.next_d = p.next_w = vec3(0.0);
  p.next_pdf_dir = p.next_p_light = 0.0;
  p.lights_left = 0u;
  p.vertex_wa = p.vertex_n = vec3(0.0);
  p.light_pending = false;
  p.delta_light = LIGHT_COUNT;
  p.L_direct = p.L_first = vec3(0.0);
  p.first_vertex = AOV_VERTEX_NONE;
  p.has_feature = false;
  p.feature_albedo = p.feature_normal = vec3(0.0);
  p.feature_depth = 0.0;
  p.vertex_norm = vec4(0.0);
  p.vertex_medium = false;
  p.vertex_d_in = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    p.vertex_share[i] = vec3(0.0);
    p.vertex_q[i] = 0.0;
  }
}

