// Free flights: transmittance estimates (ratio and delta tracking) and the
// path's free flights up to its next event (path_track).
// Below this running transmittance estimate, ratio tracking plays Russian
// roulette (transmittance() and light rays).
const float RATIO_TRACKING_ROULETTE_BELOW = 0.1;

// Transmittance along a ray to infinity, per channel. Ratio tracking (Novák et
// al. 2014): multiply by the null fraction sigma_n/sigma_maj at every tentative
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
    float sigma_maj = majorant_at(o, d, t, span, false, t_next, any_ahead);
    if (!any_ahead || isinf(t_next)) return T;
    if (sigma_maj <= 0.0) { t = t_next; continue; }
    float dt = sample_free_flight(sigma_maj, rng_next(rng));
    if (t + dt >= t_next) { t = t_next; continue; }
    t += dt;
    MediumPoint mp;
    coefficients_at(o + t * d, t, span, true, mp, stats, rng);
    vec3 sigma_n = max(vec3(sigma_maj) - mp.sigma_a - mp.sigma_s, vec3(0.0));
    if (ratio) {
      T *= sigma_n / sigma_maj;
      float q = max3(T);
      if (q < RATIO_TRACKING_ROULETTE_BELOW) {  // Russian roulette: survive with probability q, reweight by 1/q
        if (rng_next(rng) >= q) return vec3(0.0);
        T /= q;
      }
    } else {
      float p_null = avg3(sigma_n * T) / (sigma_maj * avg3(T));
      if (rng_next(rng) >= p_null) return vec3(0.0);
      T *= sigma_n / (sigma_maj * p_null);
    }
  }
  return T;
}

// The events path_track ends a ray segment with (EVENT_NONE: EARLY_EVENT_EXIT
// left the free-flight loop before this lane found its event).
const uint EVENT_NONE = 0u, EVENT_ESCAPE = 1u, EVENT_SURFACE = 2u, EVENT_ABSORB = 3u, EVENT_SCATTER = 4u,
           EVENT_END = 5u;
// What path_event needs of the real collision path_track found.
struct Collision {
  vec3 x, sigma_s;
  float sigma_maj, p_a, p_s;
  vec3 sigma_a;  // read only for film.aovs' albedo (the wavefront does not carry it)
};

// Scenes whose only medium is one grid: path_track's free flights walk its
// majorant cells in one pass (grid_free_flight).
const bool ONE_GRID = HAS_GRIDS && !HAS_ANALYTIC_MEDIA && MEDIUM_COUNT == 1u;

// Free flights along the current ray until its event (path_step's loop).
//
// Delta tracking against a piecewise-constant majorant: the ray is split at
// media boundaries and majorant-cell faces, and free flights restart at each
// (memoryless); with ONE_GRID a flight spends one sampled optical depth
// across the cells instead (grid_free_flight), the same distribution. RGB
// sigma is handled by spectral tracking (Kutz et al. 2017, "Spectral and
// Decomposition Tracking", history-aware averaged probabilities):
// distances are sampled with the grey majorant sigma_maj, and event x (absorb /
// scatter / null) is chosen with P_x = avg(sigma_x ⊙ w) / (sigma_maj·avg(w)); the
// path weight w then picks up sigma_x / (sigma_maj·P_x) per channel. For grey
// media every factor is 1 and this is plain delta tracking.
uint path_track(inout PathState p, vec2 span[MEDIA_N], inout uint rng, inout PathStats stats, out Collision c_out,
                out MediumPoint mp) {
  // Free flights, until the ray meets what needs more than a density lookup:
  // a surface, a real event, the end of the media, a light ray's lost
  // roulette. The cheap steps loop here and the event code runs once per
  // event (docs/rendering.md "llvmpipe workarounds": while-while; no return inside a loop).
  //
  // Each pass of the loop is one free flight of every lane still looking for
  // its event (the do-while(false) body: `continue` and `break` there end the
  // flight). The lanes that have theirs wait, masked, for the others. With
  // EARLY_EVENT_EXIT the group leaves once half of its lanes are done; the
  // others keep their ray and position and go on at the next call (free
  // flights are memoryless). Each path sees the same random numbers either
  // way, so the image is bit-identical.
  uint event = EVENT_NONE;
  float sigma_maj = 0.0, p_a = 0.0, p_s = 0.0;
  vec3 x = vec3(0.0);
  mp.sigma_a = mp.sigma_s = vec3(0.0);
  for (;;) {
    if (event == EVENT_NONE) do {
      const float t_surface = p.has_hit ? p.hit.t : INF;
      if (ONE_GRID) {
        // The flight walks the majorant cells itself (grid_free_flight).
        // Media beyond the closest surface do not matter: free flights end there.
        const vec2 s = span[0];
        if (p.t < s.x && !(p.has_hit && t_surface <= s.x)) p.t = s.x;
        if (p.t >= s.y || p.t < s.x) {  // past the grid, or a surface before it
          event = p.has_hit ? EVENT_SURFACE : EVENT_ESCAPE;
          break;
        }
        const float t_end = min(s.y, t_surface);
        sigma_maj = grid_free_flight(media[0], p.o, p.d, p.t, t_end, COLLISION_ESTIMATOR, -log(1.0 - rng_next(rng)));
        if (sigma_maj <= 0.0) {
          // Out of the grid (the surface, or nothing, beyond), or out of walk
          // steps: a fresh flight from p.t.
          if (p.t >= t_end) event = p.has_hit ? EVENT_SURFACE : EVENT_ESCAPE;
          continue;
        }
      } else {
        // Restarted at every majorant-cell face and media boundary.
        float t_next;
        bool any_ahead;
        sigma_maj = majorant_at(p.o, p.d, p.t, span, COLLISION_ESTIMATOR, t_next, any_ahead);
        if (!any_ahead) t_next = INF;
        if (isinf(t_next) && !p.has_hit) {
          event = EVENT_ESCAPE;
          break;
        }
        const float t_end = min(t_next, t_surface);
        float dt = sigma_maj > 0.0 ? sample_free_flight(sigma_maj, rng_next(rng)) : INF;
        if (p.t + dt >= t_end) {
          if (p.has_hit && t_surface <= t_next) {
            event = EVENT_SURFACE;
            break;
          }
          p.t = t_next;
          continue;
        }
        p.t += dt;
      }
      x = p.o + p.t * p.d;
      // The collision estimator collects emission at every tentative collision: it
      // reads the trilinear density and temperature there.
      coefficients_at(x, p.t, span, !COLLISION_ESTIMATOR, mp, stats, rng);
      if (HAS_EMISSION && COLLISION_ESTIMATOR && !p.skip_segment) {
        // Collision estimator (pbrt-v4 volpath): sigma_a·Le/sigma_maj at every tentative collision;
        // the line estimator is this one with sigma_maj raised to the line rates (grid_majorant).
        // With next-event estimation the ray's own MIS weight (light rays: 1). A skipped
        // segment (ratio-tracked continuation) was already collected: no lookup.
        vec3 e = emission_at(x, p.t, span, mp);
        if (max3(e) > 0.0) p.L += (unidirectional_weight(p.pdf_dir, p.p_light) / sigma_maj) * p.w * e;
      }
      vec3 sigma_n = max(vec3(sigma_maj) - mp.sigma_a - mp.sigma_s, vec3(0.0));
      if (NEE && p.light_ray) {
        // Light rays: ratio tracking (docs/mis.md "Light rays"): no event is
        // chosen, the weight takes the null fraction, Russian roulette once the
        // ray's transmittance estimate is below RATIO_TRACKING_ROULETTE_BELOW.
        const vec3 null_fraction = sigma_n / sigma_maj;
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
      float c = sigma_maj * avg3(p.w);
      p_a = avg3(mp.sigma_a * p.w) / c;
      p_s = HAS_SCATTERING ? avg3(mp.sigma_s * p.w) / c : 0.0;
      // A real collision scatters whenever it can (implicit capture,
      // docs/mis.md "No absorption events"): the scattering's weight
      // sigma_s / (sigma_maj·(P_a + P_s)) keeps the expectation, and the
      // emission an absorption here would have collected is collected as its
      // expected value, by the collision estimator already or by path_event.
      if (p_s > 0.0) {
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
      p.w *= sigma_n / (sigma_maj * (1.0 - p_a - p_s));
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
  c_out = Collision(x, mp.sigma_s, sigma_maj, p_a, p_s, mp.sigma_a);
  return event;
}
