// Next-event estimation's light choice and the MIS weights (docs/mis.md):
// the lights' normalisers and solid-angle pdfs seen from a vertex, a light
// direction drawn from them, the continuation's mixture pdf.
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

// The normalisers of the emissive grids' light distributions seen from
// vertex o (emission_receiver_norm), by grid slot: computed once per vertex.
void light_norms(vec3 o, out vec4 norm) {
  norm = vec4(0.0);
  if (HAS_GRIDS && HAS_EMISSION)
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      if (!is_grid(media[i])) continue;
      const uint slot = media[i].grid_slot;
      if (emission_lights[slot].pick_probability > 0.0) norm[slot] = emission_receiver_norm(emission_lights[slot], o);
    }
}

// The solid-angle pdf with which next-event estimation at o picks direction
// d (docs/mis.md): the environment map's, and each emissive grid's pdf of the
// direction toward a point of its emission CDF seen from o, mixed by the
// light choice. norm: light_norms(o).
float light_direction_pdf(vec3 o, vec4 norm, vec3 d) {
  float p = 0.0;
  if (HAS_ENVIRONMENT && frame.p_env > 0.0) p += frame.p_env * env_pdf(environment, d);
  if (HAS_GRIDS && HAS_EMISSION)
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      if (!is_grid(media[i])) continue;
      GpuEmissionCdf e = emission_lights[media[i].grid_slot];
      if (e.pick_probability > 0.0) p += e.pick_probability * emission_direction_pdf(e, o, norm[media[i].grid_slot], d);
    }
  for (uint i = 0u; i < LIGHT_COUNT; ++i)
    if (analytic_lights[i].pick_probability > 0.0) p += analytic_lights[i].pick_probability * analytic_light_pdf(analytic_lights[i], o, d);
  return p;
}

// A light direction for next-event estimation from point o: the environment
// map's, toward a point drawn from an emissive grid's emission CDF, or toward
// an analytic light (the light chosen by frame.p_env, each grid's
// pick_probability and each analytic light's). false: none. A delta light
// sets delta_light to its index and delta_w to what it delivers along dir per
// unit of f, over its probability; otherwise delta_light = LIGHT_COUNT.
bool sample_light_direction(vec3 o, vec4 norm, inout uint rng, out vec3 dir, out vec3 delta_w, out uint delta_light) {
  dir = vec3(0.0, 0.0, 1.0);
  delta_w = vec3(0.0);
  delta_light = LIGHT_COUNT;
  float u = rng_next(rng);
  vec2 u2 = vec2(rng_next(rng), rng_next(rng));
  float u_z = rng_next(rng);
  if (HAS_ENVIRONMENT && u < frame.p_env) {
    EnvSample es = env_sample(environment, u2);
    dir = es.dir;
    return es.pdf > 0.0;
  }
  u -= frame.p_env;
  // The grid medium whose light probability covers u.
  // (The last light when rounding leaves u past them all, like the CPU reference.)
  uint pick = MEDIUM_COUNT;
  bool found = false;
  if (HAS_GRIDS && HAS_EMISSION)
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      if (!is_grid(media[i])) continue;
      float p = emission_lights[media[i].grid_slot].pick_probability;
      if (!(p > 0.0) || found) continue;
      pick = i;
      if (u < p) found = true; else u -= p;
    }
  if (LIGHT_COUNT > 0u && !found) {
    // Past the grids: the analytic light whose probability covers u (the last one when rounding leaves u past them).
    uint light = LIGHT_COUNT;
    for (uint i = 0u; i < LIGHT_COUNT; ++i) {
      const float p = analytic_lights[i].pick_probability;
      if (!(p > 0.0) || found) continue;
      light = i;
      if (u < p) found = true; else u -= p;
    }
    if (light < LIGHT_COUNT) {
      const GpuLight l = analytic_lights[light];
      vec3 delta_value;
      if (!analytic_light_sample(l, o, u2, dir, delta_value)) return false;
      if (light_is_delta(l.kind)) {
        delta_light = light;
        delta_w = delta_value / l.pick_probability;
      }
      return true;
    }
  }
  if (!HAS_GRIDS || !HAS_EMISSION || pick == MEDIUM_COUNT) return false;
  const uint slot = media[pick].grid_slot;
  const float u_cluster = rng_next(rng), u_cell = rng_next(rng);
  EmissionSample es = emission_sample(emission_lights[slot], o, norm[slot], u_cluster, u_cell, vec3(u2, u_z));
  if (!(es.pdf > 0.0)) return false;
  vec3 v = es.p - o;
  float dist = length(v);
  if (!(dist > 0.0)) return false;
  dir = v / dist;
  return true;
}

// The continuation's solid-angle pdf of a direction that the vertex's lobe
// draws with pdf_own and the lights with p_light (docs/mis.md eq. 5).
float continuation_pdf(float pdf_own, float p_light) {
  const float c = frame.p_continue_own;
  return c * pdf_own + (1.0 - c) * p_light;
}

// The phase function of a scattering mixture from d_in toward w: its value
// f = Σ_i share_i·HG_i (per channel) and the pdf with which the vertex samples
// w, Σ_i q_i·HG_i (lobe i picked with probability q_i).
void phase_mixture(vec3 d_in, vec3 w, vec3 share[MEDIA_N], float q[MEDIA_N], out vec3 f, out float pdf) {
  f = vec3(0.0);
  pdf = 0.0;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    float hg = hg_pdf(dot(d_in, w), media[i].g);
    f += share[i] * hg;
    pdf += q[i] * hg;
  }
}
