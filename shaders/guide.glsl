// The denoiser's guide (film.aovs; docs/compositing.md "Denoiser"): what a
// camera ray sees without scattering, computed without random numbers. Up to
// the first surface or sphere light, the media's emission,
//   L = ∫ T(t) Σ σa·Le dt,  T(t) = exp(−∫ σt),
// then what ends the ray times T: a sphere light's radiance, or the
// background (environment, sun discs) unless film.transparent, or nothing at
// a surface. That is the expected value of the `emission` plus `background`
// layers for that ray; alpha is 1 − avg(T), with T = 0 at a surface or a
// sphere light. A ray march at midpoints, each step exact for constant
// coefficients:
//   L += T·E/σt·(1 − e^(−σt·Δt)),  T ·= e^(−σt·Δt).
// With one dense grid (guide_one_grid), equal steps of at most a density
// texel over the medium's whole span, as the CPU reference takes them; with
// other media (guide_media), equal steps of at most a texel through each
// non-empty majorant cell, empty cells skipped, a homogeneous medium one
// step per segment.
// Its only noise is the sample's film position, so the guide tells the
// fire's structure (and the background through the smoke) from the path
// tracer's noise.
const uint GUIDE_MAX_STEPS = 4096u;
// Past this transmittance in every channel the march stops: what lies behind
// adds at most this fraction of its own light (docs/compositing.md "The guide").
const float GUIDE_MIN_TRANSMITTANCE = 1e-6;

// One march step over [t, t + dt) at its midpoint, exact for constant
// coefficients.
void guide_step(vec3 E, vec3 sigma_t, float dt, inout vec3 L, inout vec3 T) {
  const vec3 tr = exp(-sigma_t * dt);
  // E·Δt where σt·Δt is too small for (1 − e^(−σt·Δt))/σt to keep its digits.
  L += T * mix(E * dt, E * (1.0 - tr) / max(sigma_t, vec3(1e-30)), greaterThan(sigma_t * dt, vec3(1e-4)));
  T *= tr;
}

// Equal steps of at most h over a piece of the ray `length` long (at least
// one, at most GUIDE_MAX_STEPS).
uint guide_steps(float length, float h) { return uint(clamp(ceil(length / h), 1.0, float(GUIDE_MAX_STEPS))); }

// One dense grid, the common case: equal steps of at most h over the span
// [t, t1) (docs/compositing.md "The guide"). Only the steps from the ray's
// first to its last non-empty majorant cell are taken: a cell with a zero
// majorant has zero density throughout, so the steps before and after add
// nothing, and the values are those of marching the whole span. Found by a
// walk over the cells without lookups, this costs far less than stepping
// cell by cell, where each cell rounds its step count up and every SIMD lane
// waits for the longest one's cell (docs/benchmarks.md "The guide's march
// on one lattice": 0.69× the guide's time on the Blender fire).
void guide_one_grid(vec3 o, vec3 d, float t, float t1, float h, inout vec3 L, inout vec3 T) {
  const GpuMedium m = media[0];
  const uint slot = m.grid_slot;
  const vec3 u0 = density_texel(slot, o), du = density_texel_dir(slot, d);
  const uint steps = guide_steps(t1 - t, h);
  const float dt = (t1 - t) / float(steps);
  // [a, b): from the first non-empty cell's entry to the last one's exit.
  float nudge;
  CellWalk w = cell_walk(slot, o, d, t, nudge);
  float a = INF, b = t, tc = t;
  for (uint n = 0u; n < GUIDE_MAX_STEPS && tc < t1; ++n) {
    const float t_next = min(min3(w.t_axis), t1);
    if (cell_majorant(slot, w, false) > 0.0 && t_next > tc) {
      a = min(a, tc);
      b = t_next;
    }
    tc = max(tc, t_next);
    if (!cell_step(w)) break;
  }
  if (!(b > a)) return;
  // The steps whose midpoints t + (j + ½)·dt can lie in [a, b), with half a
  // step to spare on each side against rounding (a step outside adds 0).
  const uint j0 = uint(clamp(floor((a - t) / dt - 0.5), 0.0, float(steps)));
  const uint j1 = uint(clamp(ceil((b - t) / dt + 0.5), 0.0, float(steps)));
  for (uint j = j0; j < j1 && max3(T) >= GUIDE_MIN_TRANSMITTANCE; ++j) {
    const float tm = t + (float(j) + 0.5) * dt;
    const vec2 v = density_at(slot, u0 + tm * du);
    const float r = grids[slot].density_scale * v.x;
    const vec3 E = r > 0.0 ? r * m.sigma_a * grid_le(m, slot, o + tm * d, v.y) : vec3(0.0);
    guide_step(E, r * (m.sigma_a + m.sigma_s), dt, L, T);
  }
}

// The media part of the guide: emission and transmittance from the media
// entry to t_end (the surface or sphere light, or INF).
void guide_media(vec3 o, vec3 d, float t_end, vec2 span[MEDIA_N], inout vec3 L, inout vec3 T) {
  float t0 = INF, t1 = 0.0, h = INF;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].y > max(span[i].x, 0.0))) continue;
    t0 = min(t0, max(span[i].x, 0.0));
    t1 = max(t1, span[i].y);
    GpuMedium m = media[i];
    if (is_grid(m)) h = min(h, 1.0 / max(length(density_texel_dir(m.grid_slot, d)), 1e-30));
  }
  t1 = min(t1, t_end);
  if (MEDIUM_COUNT == 1u && is_grid(media[0]) && !(SPARSE_GRIDS && grids[media[0].grid_slot].density.tree != 0u)) {
    guide_one_grid(o, d, t0, t1, h, L, T);
    return;
  }
  PathStats stats = PathStats(0.0, 0.0);
  float t = t0;
  uint n = 0u;  // steps taken
  while (n < GUIDE_MAX_STEPS && t < t1 && max3(T) >= GUIDE_MIN_TRANSMITTANCE) {
    // One majorant cell (or run of empty cells) per pass of this loop: the
    // majorant is looked up once per cell, not once per step.
    float t_next;
    bool ahead;
    const float majorant = majorant_at(o, d, t, span, false, t_next, ahead);
    if (!ahead) break;
    t_next = min(t_next, t1);
    if (!(majorant > 0.0)) {  // nothing here up to t_next
      t = t_next;
      ++n;
      continue;
    }
    // Equal steps of at most h through the cell, each at its midpoint.
    const uint steps = guide_steps(t_next - t, h);
    const float dt = (t_next - t) / float(steps);
    for (uint j = 0u; j < steps && n < GUIDE_MAX_STEPS; ++j, ++n) {
      const float tm = t + (float(j) + 0.5) * dt;
      const vec3 x = o + tm * d;
      uint no_rng = 0u;  // the guide's march reads the trilinear density
      MediumPoint mp;
      coefficients_at(x, tm, span, false, mp, stats, no_rng);
      guide_step(emission_at(x, tm, span, mp), mp.sigma_a + mp.sigma_s, dt, L, T);
    }
    t = t_next;
  }
}

void guide_march(vec3 o, vec3 d, out vec3 L, out vec3 T) {
  L = vec3(0.0);
  T = vec3(1.0);
  SurfaceHit hit;
  const bool surface = HAS_SURFACES && intersect_surfaces(o, d, INF, hit);
  float t_end = surface ? hit.t : INF;
  const uint light = LIGHT_COUNT > 0u ? intersect_sphere_lights(o, d, t_end) : LIGHT_COUNT;
  vec2 span[MEDIA_N];
  bool any_hit;
  media_spans(o, d, span, any_hit);
  if (any_hit) guide_media(o, d, t_end, span, L, T);
  if (light < LIGHT_COUNT) {
    L += T * sphere_light_radiance(analytic_lights[light], o + t_end * d, d);
    T = vec3(0.0);
  } else if (surface) {
    T = vec3(0.0);
  } else if (frame.transparent == 0u) {
    L += T * escaped_radiance(d);
  }
}
