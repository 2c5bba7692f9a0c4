// A scattering vertex (surface or medium): its light rays (next-event
// estimation, drawn one at a time by next_light_ray) and its continuation.
// Once the scatterings that implicit capture keeps from being absorbed have
// lowered a path's weight below this fraction, Russian roulette
// (scatter_vertex; docs/mis.md "No absorption events").
const float SCATTER_ROULETTE_BELOW = 0.1;

// The next of a vertex's light rays (docs/mis.md "Several light samples"),
// drawn by path_begin: a light direction from the vertex, its
// weight w·f·MIS weight / (n·p_light) for the vertex's n light samples (a
// surface's frame.surface_light_samples, a medium vertex's 1); weight 0 when no light
// direction was found (the ray then ends at once). The only copy of the
// light-sampling code, one draw per call and no loop (docs/rendering.md "llvmpipe workarounds": one copy of the
// light code; no return inside a loop).
void next_light_ray(inout PathState p, inout uint rng) {
  const float n = p.vertex_medium ? 1.0 : float(frame.surface_light_samples);
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

// Whether a vertex draws its continuation from the lights (with next-event
// estimation, probability 1 − frame.p_continue_own; docs/mis.md "Guided
// continuation") and, if so, the direction. false with dir unset: its own lobe.
bool continue_toward_light(vec3 o, vec4 norm, inout uint rng, out vec3 dir, out bool none) {
  dir = vec3(0.0, 0.0, 1.0);
  none = false;
  if (!NEE || !GUIDED_CONTINUATION || rng_next(rng) < frame.p_continue_own) return false;
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
  p.continuation_ray = frame.ratio_tracked_continuation != 0u && lights_after > 0u && !p.vertex_medium
                         ? CONTINUATION_PENDING : CONTINUATION_PLAIN;
  p.light_ray = true;
  return ray_ends(p);  // the first light ray, or the continuation
}

// A scattering vertex: a Lambertian bounce at the surface ahead (surface;
// weight × albedo, as cosine sampling's pdf cancels the cosine and 1/π, the
// new direction on the side the ray came from: surfaces are two-sided) or a
// real scattering collision at x in the media. Returns true when the path
// ends. Both kinds share one copy of the light code (the receiver
// normalisers, leave_vertex's light pdf; their light rays are drawn by
// next_light_ray; docs/rendering.md "llvmpipe workarounds": one copy of the light code).
bool scatter_vertex(inout PathState p, bool surface, vec3 x, vec3 sigma_s, float sigma_maj, float p_s,
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
    GpuMaterial m = surface_materials[si.material];
    albedo = m.albedo;
    if (ALBEDO_TEXTURE_COUNT > 0u && m.texture_slot != NO_TEXTURE)
      albedo *= albedo_texture_at(m.texture_slot, vec2(si.uv.x, 1.0 - si.uv.y));  // OBJ v=0 at the bottom
    n = dot(si.normal, p.d) < 0.0 ? si.normal : -si.normal;
    set_features(p, albedo, n, si.position);
    if (p.depth >= frame.max_depth) return true;  // max_depth reached
    ++p.depth;
    o = offset_ray_origin(si.position, n);
  } else {
    if (p.depth >= frame.max_depth) return true;  // max_depth reached
    ++p.depth;
    const float w_before = max3(p.w);
    p.w *= sigma_s / (sigma_maj * p_s);
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
    // Phase function of the mixture f = Σ_i share_i·HG_i, share_i = σs_i/σs (per
    // channel): sample lobe i with q_i ∝ avg(share_i ⊙ w); the direction's pdf
    // is the mixture's, Σ_i q_i·HG_i, and the weight f/pdf.
    vec3 inv_sigma_s = 1.0 / max(sigma_s, vec3(1e-30));
    float total = 0.0;
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
      share[i] = rho[i] * media[i].sigma_s * inv_sigma_s;
      q[i] = avg3(share[i] * p.w);
      total += q[i];
    }
    for (uint i = 0u; i < MEDIUM_COUNT; ++i) q[i] /= total;
  }
  if (AOVS && p.depth == 1u) {  // the path's first vertex: what follows is its scatter or surface layer
    p.L_first = p.L;
    p.first_vertex = surface ? AOV_VERTEX_SURFACE : AOV_VERTEX_MEDIUM;
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
        g = media[i].g;
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
    lights_after = NEE && max3(p.w * albedo) > 0.0 ? frame.surface_light_samples : 0u;
    n_light = max(lights_after, 1u);
  } else {
    if (!NEE && MEDIUM_COUNT == 1u) {
      // One lobe, sampled exactly (q[0] = 1): its HG value cancels in the
      // weight f/pdf, and no MIS weight needs the pdf (docs/rendering.md
      // "llvmpipe workarounds": every branch runs, so skip the evaluation).
      f = share[0];
      pdf_own = 1.0;
    } else {
      phase_mixture(p.d, d, share, q, f, pdf_own);
    }
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
