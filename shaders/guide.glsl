// The denoiser's guide (film.aovs; docs/compositing.md "Denoiser"): along a
// camera ray, the media's emission that reaches the camera unscattered,
//   L = ∫ T(t) Σ σa·Le dt,  T(t) = exp(−∫ σt),
// up to the first surface, and the transmittance T to the background (0 when
// a surface ends the ray): the expected value of the `emission` layer and of
// alpha, 1 − avg(T), for that ray, computed without random numbers. A ray march at midpoints, about one density texel per step inside
// non-empty majorant cells (empty cells are skipped, a homogeneous medium is
// one step per segment), each step exact for constant coefficients:
//   L += T·E/σt·(1 − e^(−σt·Δt)),  T ·= e^(−σt·Δt).
// Its only noise is the sample's film position, so the guide tells the
// fire's structure from the path tracer's noise.
const uint GUIDE_MAX_STEPS = 4096u;

void guide_march(vec3 o, vec3 d, out vec3 L, out vec3 T) {
  L = vec3(0.0);
  T = vec3(1.0);
  SurfaceHit hit;
  const bool surface = intersect_surfaces(o, d, INF, hit);
  vec2 span[MEDIA_N];
  bool any_hit;
  media_spans(o, d, span, any_hit);
  if (!any_hit) {
    if (surface) T = vec3(0.0);
    return;
  }
  float t0 = INF, t1 = 0.0, h = INF;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].y > max(span[i].x, 0.0))) continue;
    t0 = min(t0, max(span[i].x, 0.0));
    t1 = max(t1, span[i].y);
    GpuMedium m = media[i];
    if (is_grid(m)) h = min(h, 1.0 / max(length(density_texel_dir(m.grid_slot, d)), 1e-30));
  }
  if (surface) t1 = min(t1, hit.t);
  PathStats stats = PathStats(0.0, 0.0);
  float t = t0;
  for (uint n = 0u; n < GUIDE_MAX_STEPS && t < t1; ++n) {
    float t_next;
    bool ahead;
    const float majorant = majorant_at(o, d, t, span, t_next, ahead);
    if (!ahead) break;
    t_next = min(t_next, t1);
    if (!(majorant > 0.0)) {  // nothing here up to t_next
      t = t_next;
      continue;
    }
    const float dt = min(h, t_next - t);
    const float tm = t + 0.5 * dt;
    const vec3 x = o + tm * d;
    vec3 sigma_a, sigma_s;
    float rho[MEDIA_N], temperature_value[MEDIA_N];
    coefficients_at(x, tm, span, sigma_a, sigma_s, rho, temperature_value, stats);
    const vec3 E = emission_at(x, tm, span, rho, temperature_value);
    const vec3 sigma_t = sigma_a + sigma_s;
    const vec3 tr = exp(-sigma_t * dt);
    // E·Δt where σt·Δt is too small for (1 − e^(−σt·Δt))/σt to keep its digits.
    L += T * mix(E * dt, E * (1.0 - tr) / max(sigma_t, vec3(1e-30)), greaterThan(sigma_t * dt, vec3(1e-4)));
    T *= tr;
    t += dt;
  }
  if (surface) T = vec3(0.0);
}
