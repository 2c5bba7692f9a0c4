// Media lookups (render.comp): density, temperature and blackbody textures,
// the media's extent along a ray, the majorant grid's DDA, the coefficients and
// the emission at a point.
// Texture arrays are indexed with constants only (no dependence on
// dynamically-uniform indexing, which lavapipe and older GPUs handle poorly).
// u: texel coordinates (density_texel). With TEMPERATURE_IN_DENSITY, .y is the
// temperature grid's value (else 0). A sparse grid reads its tree instead.
vec2 density_at(uint slot, vec3 u) {
  if (GRID_COUNT <= 1u) slot = 0u;
  if (SPARSE_GRIDS && grids[slot].density.tree != 0u)
    return vec2(sparse_trilinear(grids[slot].density.leaf_table, grids[slot].density.leaf_origin,
                                 grids[slot].density.leaf_dims, u + grids[slot].density.index_origin),
                0.0);
  const vec3 tc = u / grids[slot].density.dims;
  vec2 v;
  switch (slot) {
    case 0u: v = textureLod(density_tex[0], tc, 0.0).rg; break;
    case 1u: v = textureLod(density_tex[1], tc, 0.0).rg; break;
    case 2u: v = textureLod(density_tex[2], tc, 0.0).rg; break;
    default: v = textureLod(density_tex[3], tc, 0.0).rg; break;
  }
  return TEMPERATURE_IN_DENSITY ? v : vec2(v.x, 0.0);
}
// The density at one texel of u's trilinear footprint, texel c + o chosen with
// probability w_o = Π_a (o_a ? f_a : 1 − f_a), the trilinear weight (c =
// floor(u − 0.5), f = u − 0.5 − c): its expectation is the trilinear value.
// Delta tracking needs no more (docs/rendering.md "Stochastic density
// lookups"): a null collision's probability is linear in the density, and
// every texel of the footprint lies under the cell's majorant. One texel fetch
// costs lavapipe far less than a filtered lookup.
float stochastic_density(uint slot, vec3 u, inout uint rng) {
  if (GRID_COUNT <= 1u) slot = 0u;
  const vec3 f0 = u - 0.5, c = floor(f0), f = f0 - c;
  const vec3 xi = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
  const ivec3 dims = ivec3(grids[slot].density.dims);
  const ivec3 texel = clamp(ivec3(c) + ivec3(lessThan(xi, f)), ivec3(0), dims - 1);
  const int index = (texel.z * dims.y + texel.y) * dims.x + texel.x;
  switch (slot) {
    case 0u: return texelFetch(density_texels[0], index).r;
    case 1u: return texelFetch(density_texels[1], index).r;
    case 2u: return texelFetch(density_texels[2], index).r;
    default: return texelFetch(density_texels[3], index).r;
  }
}
// The temperature grid's stored value at index-space u, before the mapping
// T = (value - offset) * scale turns it into kelvin (emission_at below).
float temperature_value_at(uint slot, vec3 u) {
  if (GRID_COUNT <= 1u) slot = 0u;
  if (SPARSE_GRIDS && grids[slot].temperature.tree != 0u)
    return sparse_trilinear(grids[slot].temperature.leaf_table, grids[slot].temperature.leaf_origin,
                            grids[slot].temperature.leaf_dims, u + grids[slot].temperature.index_origin);
  const vec3 tc = u / grids[slot].temperature.dims;
  switch (slot) {
    case 0u: return textureLod(temperature_tex[0], tc, 0.0).r;
    case 1u: return textureLod(temperature_tex[1], tc, 0.0).r;
    case 2u: return textureLod(temperature_tex[2], tc, 0.0).r;
    default: return textureLod(temperature_tex[3], tc, 0.0).r;
  }
}
vec3 blackbody_at(uint slot, float s) {
  if (GRID_COUNT <= 1u) slot = 0u;
  switch (slot) {
    case 0u: return textureLod(blackbody_tex[0], s, 0.0).rgb;
    case 1u: return textureLod(blackbody_tex[1], s, 0.0).rgb;
    case 2u: return textureLod(blackbody_tex[2], s, 0.0).rgb;
    default: return textureLod(blackbody_tex[3], s, 0.0).rgb;
  }
}

vec3 density_texel(uint slot, vec3 p) {
  vec4 p1 = vec4(p, 1.0);
  return vec3(dot(grids[slot].density.row0, p1), dot(grids[slot].density.row1, p1), dot(grids[slot].density.row2, p1));
}
vec3 density_texel_dir(uint slot, vec3 d) {
  vec4 d0 = vec4(d, 0.0);
  return vec3(dot(grids[slot].density.row0, d0), dot(grids[slot].density.row1, d0), dot(grids[slot].density.row2, d0));
}

// A grid's stored temperature value in kelvin, T = (value − offset)·scale: the
// one GLSL copy of the mapping (the host's is TemperatureMapping::kelvin).
float temperature_kelvin(uint slot, float value) {
  return (value - grids[slot].temperature_offset) * grids[slot].temperature_scale;
}

// Emitted radiance Le of grid medium m at world point x (docs/scene-format.md "media": T = (v − offset)·scale,
// no emission at or below cutoff_k; the LUT is uniform in ln T). With
// TEMPERATURE_IN_DENSITY the grid's value v was read with the density at x.
vec3 grid_le(GpuMedium m, uint slot, vec3 x, float value_read) {
  uint mode = m.emission_mode;
  if (mode == EMIT_CONSTANT) return m.emission;
  if (mode != EMIT_TEMPERATURE) return vec3(0.0);
  float value = value_read;
  if (!TEMPERATURE_IN_DENSITY) {
    vec4 p1 = vec4(x, 1.0);
    vec3 u = vec3(dot(grids[slot].temperature.row0, p1), dot(grids[slot].temperature.row1, p1),
                  dot(grids[slot].temperature.row2, p1));
    value = temperature_value_at(slot, u);
  }
  const float T = temperature_kelvin(slot, value);
  if (!(T > grids[slot].cutoff_k) || !(T >= grids[slot].t_min_k)) return vec3(0.0);
  return m.emission * blackbody_at(slot, log(T) * grids[slot].lut_scale + grids[slot].lut_offset);
}

// The media's extent along a ray: [t_enter, t_exit], (-1,-1) when missed.
void media_spans(vec3 o, vec3 d, out vec2 span[MEDIA_N], out bool any_hit) {
  any_hit = false;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    GpuMedium m = media[i];
    uint shape = m.shape;
    vec2 t;
    bool hit;
    if (is_grid(m)) {
      // The texel box [0, dims] in texel space; t is the same there (affine map).
      uint slot = m.grid_slot;
      // Clip to the trilinear support, between the zero padding texels' centres
      // (u = 0.5 .. dims − 0.5): outside it every lookup is 0, and a dense grid's
      // majorant there would only buy null collisions.
      hit = intersect_box(density_texel(slot, o), density_texel_dir(slot, d), vec3(0.5),
                          grids[slot].density.dims - 0.5, t);
    } else if (shape == SHAPE_SPHERE) {
      hit = intersect_sphere(o, d, m.center, m.radius, t);
    } else {
      hit = intersect_box(o, d, m.box_min, m.box_max, t);
    }
    span[i] = hit ? t : vec2(-1.0);
    any_hit = any_hit || hit;
  }
}

// A 3D DDA over a grid's majorant cells (Amanatides & Woo 1987): the cell the
// ray o + t·d is in and where it crosses each axis' next face. Stateless
// start: the cell is found at t + a small nudge along the ray, so a point on
// a face belongs to the cell being entered.
struct CellWalk {
  ivec3 cell, res, dir;
  vec3 t_axis, t_delta;
  uint offset;  // cell (0,0,0)'s index in the majorant buffer
};

CellWalk cell_walk(uint slot, vec3 o, vec3 d, float t, out float nudge) {
  CellWalk w;
  const vec3 u = density_texel(slot, o + t * d), du = density_texel_dir(slot, d);
  const vec3 cs = grids[slot].majorant_cell, inv_du = 1.0 / du;
  nudge = 1e-4 * min3(cs) / max(max3(abs(du)), 1e-30);
  w.res = ivec3(grids[slot].majorant_res);
  w.offset = grids[slot].majorant_offset;
  w.cell = clamp(ivec3(floor((u + du * nudge) / cs)), ivec3(0), w.res - 1);
  const vec3 tx = ((vec3(w.cell) + step(vec3(0.0), du)) * cs - u) * inv_du;
  w.t_axis = t + mix(tx, vec3(INF), isnan(tx));  // ±inf on axes the ray runs parallel to
  w.t_delta = abs(cs * inv_du);
  w.dir = ivec3(sign(du));
  return w;
}

uint cell_local(CellWalk w) { return uint((w.cell.z * w.res.y + w.cell.y) * w.res.x + w.cell.x); }

// Into the next cell along the ray; false once the ray has left the grid.
bool cell_step(inout CellWalk w) {
  const int a = w.t_axis.x <= w.t_axis.y ? (w.t_axis.x <= w.t_axis.z ? 0 : 2) : (w.t_axis.y <= w.t_axis.z ? 1 : 2);
  w.cell[a] += w.dir[a];
  if (w.cell[a] < 0 || w.cell[a] >= w.res[a]) return false;
  w.t_axis[a] += w.t_delta[a];
  return true;
}

// A cell's majorant; with `line` and the grid's line rates (the line
// estimator; docs/rendering.md "Emission estimators") the larger of it and the
// cell's rate, so the tentative collisions, where the collision estimator
// collects emission, come at least as often as the emission asks for.
float cell_majorant(uint slot, CellWalk w, bool line) {
  const uint local = cell_local(w), rates = grids[slot].line_rate_offset;
  const float sigma_maj = majorant_value(w.offset + local) * grids[slot].majorant_scale;
  return line && rates != 0u ? max(sigma_maj, majorant_value(rates + local)) : sigma_maj;
}

// Majorant of grid medium m over the DDA cell the ray is in at t, and the t at
// which the ray leaves that cell (the scenes with more than one medium:
// path_track restarts the free flight at every cell face).
float grid_majorant(GpuMedium m, vec3 o, vec3 d, float t, float t_span_end, bool line, inout float t_next) {
  const uint slot = m.grid_slot;
  float nudge;
  CellWalk w = cell_walk(slot, o, d, t, nudge);
  // At least a few float ulps of t, so t always moves on (a far camera loses
  // precision in u; see also the origin shift in path_begin).
  const float min_step = max(nudge, abs(t) * 1e-6);
  if (majorant_value(w.offset + cell_local(w)) > 0.0) {
    t_next = min(t_next, max(min3(w.t_axis), t + min_step));
    return cell_majorant(slot, w, line);
  }
  // An empty cell: walk the DDA on to the first non-empty cell (or out of the
  // grid) right here, so a run of empty cells costs one tracking step.
  float t_enter = min3(w.t_axis);
  for (uint n = 0u; n < 256u && t_enter < t_span_end; ++n) {
    if (!cell_step(w)) {
      t_enter = INF;  // left the grid: empty up to the span's end
      break;
    }
    if (majorant_value(w.offset + cell_local(w)) > 0.0) break;
    t_enter = min3(w.t_axis);
  }
  t_next = min(t_next, max(t_enter, t + min_step));
  return 0.0;
}

// One free flight of delta tracking through grid medium m's majorant cells,
// for scenes whose only medium is that grid (path_track): one exponential
// optical depth tau = −ln(1 − u) for the whole flight, spent cell by cell
// along the DDA (tau = Σ_j sigma_maj_j·Δt_j), so crossing a cell costs one DDA
// step instead of a pass of the tracking loop and its density lookup. The
// same distribution as restarting the flight at every face (the exponential
// is memoryless). Returns the majorant of the cell the flight collides in,
// with t moved to the collision; or 0 with t moved to t_end, or to where the
// walk's step budget ran out (the caller draws a fresh flight from there).
float grid_free_flight(GpuMedium m, vec3 o, vec3 d, inout float t, float t_end, bool line, float tau) {
  const uint slot = m.grid_slot;
  float nudge;
  CellWalk w = cell_walk(slot, o, d, t, nudge);
  for (uint n = 0u; n < 256u; ++n) {
    const float sigma_maj = cell_majorant(slot, w, line);
    const float t_exit = min(min3(w.t_axis), t_end);
    const float depth = sigma_maj * max(t_exit - t, 0.0);
    if (depth > tau) {
      t += tau / sigma_maj;
      return sigma_maj;
    }
    tau -= depth;
    t = max(t, t_exit);
    if (t >= t_end || !cell_step(w)) {
      t = t_end;
      break;
    }
  }
  return 0.0;
}

// Media coefficients at a tentative collision; rho[i] keeps each grid's
// density_scale · density for the scattering-lobe choice, and
// temperature_value[i] its temperature grid's value where the density lookup
// reads it (TEMPERATURE_IN_DENSITY; else 0). With `stochastic` and
// STOCHASTIC_DENSITY the grids' densities are stochastic_density's unbiased
// one-texel estimates, and temperature_value is 0 (event_temperatures reads it
// where the path has its event).
void coefficients_at(vec3 x, float t, vec2 span[MEDIA_N], bool stochastic, out vec3 sigma_a, out vec3 sigma_s,
                     out float rho[MEDIA_N], out float temperature_value[MEDIA_N], inout PathStats stats,
                     inout uint rng) {
  sigma_a = vec3(0.0);
  sigma_s = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    rho[i] = 0.0;
    temperature_value[i] = 0.0;
    if (!(span[i].x <= t && t < span[i].y)) continue;
    GpuMedium m = media[i];
    float r = 1.0;
    if (is_grid(m)) {
      uint slot = m.grid_slot;
      const vec2 v = STOCHASTIC_DENSITY && stochastic ? vec2(stochastic_density(slot, density_texel(slot, x), rng), 0.0)
                                                      : density_at(slot, density_texel(slot, x));
      r = grids[slot].density_scale * v.x;
      temperature_value[i] = v.y;
      stats.lookups += 1.0;
    }
    rho[i] = r;
    sigma_a += r * m.sigma_a;
    sigma_s += r * m.sigma_s;
  }
}

// The temperature values at x that a stochastic coefficients_at left out
// (TEMPERATURE_IN_DENSITY reads them with the density; otherwise grid_le reads
// its own texture): the emission needs the trilinear value, since Le is not
// linear in T.
void event_temperatures(vec3 x, float t, vec2 span[MEDIA_N], inout float temperature_value[MEDIA_N]) {
  if (!STOCHASTIC_DENSITY || !TEMPERATURE_IN_DENSITY) return;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].x <= t && t < span[i].y) || !is_grid(media[i])) continue;
    const uint slot = media[i].grid_slot;
    temperature_value[i] = density_at(slot, density_texel(slot, x)).y;
  }
}

// Emitted power per unit length, Σ sigma_a_i(x)·Le_i(x), over the media at t.
vec3 emission_at(vec3 x, float t, vec2 span[MEDIA_N], float rho[MEDIA_N], float temperature_value[MEDIA_N]) {
  vec3 E = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].x <= t && t < span[i].y)) continue;
    GpuMedium m = media[i];
    if (is_grid(m)) {
      if (rho[i] > 0.0) E += rho[i] * m.sigma_a * grid_le(m, m.grid_slot, x, temperature_value[i]);
    } else {
      E += m.emission;
    }
  }
  return E;
}

// Local majorant over [t, t_next): sum over the media present of their bound
// (with `line`, grids' line rates included: grid_majorant).
float majorant_at(vec3 o, vec3 d, float t, vec2 span[MEDIA_N], bool line, out float t_next, out bool any_ahead) {
  float sigma_maj = 0.0;
  t_next = INF;
  any_ahead = false;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    vec2 s = span[i];
    if (s.y <= t) continue;
    any_ahead = true;
    if (s.x > t) {
      t_next = min(t_next, s.x);
      continue;
    }
    t_next = min(t_next, s.y);
    GpuMedium m = media[i];
    if (is_grid(m)) sigma_maj += grid_majorant(m, o, d, t, s.y, line, t_next);
    else {
      // A homogeneous medium's line rate: line_points along the ray's chord through it.
      const float chord = s.y - max(s.x, 0.0);
      const float sigma_t = max3(m.sigma_a + m.sigma_s);
      sigma_maj += line && m.line_points > 0.0 && chord > 0.0 ? max(sigma_t, m.line_points / chord) : sigma_t;
    }
  }
  return sigma_maj;
}
