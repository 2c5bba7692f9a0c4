// Media lookups (render.comp): density, temperature and blackbody textures,
// the media's extent along a ray, the coefficients and the emission at a
// point. The majorants along a ray are majorant_walk.glsl's.
// Texture arrays are indexed with constants only (no dependence on
// dynamically-uniform indexing, which lavapipe and older GPUs handle poorly).
// `return lookup(i)` for the constant index i that equals slot (the grid
// texture arrays hold MAX_GRIDS = 4).
#define RETURN_GRID_SLOT(slot, lookup) \
  switch (slot) {                      \
    case 0u: return lookup(0);         \
    case 1u: return lookup(1);         \
    case 2u: return lookup(2);         \
    default: return lookup(3);         \
  }

// The dense density texture of a grid slot at texture coordinates tc (.y:
// the temperature, where TEMPERATURE_IN_DENSITY puts it there).
vec2 density_texture_at(uint slot, vec3 tc) {
#define DENSITY_LOOKUP(i) textureLod(density_tex[i], tc, 0.0).rg
  RETURN_GRID_SLOT(slot, DENSITY_LOOKUP)
#undef DENSITY_LOOKUP
}
// u: texel coordinates (density_texel). With TEMPERATURE_IN_DENSITY, .y is the
// temperature grid's value (else 0). A sparse grid reads its tree instead.
vec2 density_at(uint slot, vec3 u) {
  if (GRID_COUNT <= 1u) slot = 0u;
  if (SPARSE_GRIDS && grids[slot].density.tree != 0u)
    return vec2(sparse_trilinear(grids[slot].density.leaf_table, grids[slot].density.leaf_origin,
                                 grids[slot].density.leaf_dims, u + grids[slot].density.index_origin),
                0.0);
  const vec3 tc = u / grids[slot].density.dims;
  const vec2 v = density_texture_at(slot, tc);
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
#define TEXEL_LOOKUP(i) texelFetch(density_texels[i], index).r
  RETURN_GRID_SLOT(slot, TEXEL_LOOKUP)
#undef TEXEL_LOOKUP
}
// The temperature grid's stored value at index-space u, before grid_kelvin
// (shaders/shared/gpu_types.h) turns it into kelvin (grid_le below).
float temperature_value_at(uint slot, vec3 u) {
  if (GRID_COUNT <= 1u) slot = 0u;
  if (SPARSE_GRIDS && grids[slot].temperature.tree != 0u)
    return sparse_trilinear(grids[slot].temperature.leaf_table, grids[slot].temperature.leaf_origin,
                            grids[slot].temperature.leaf_dims, u + grids[slot].temperature.index_origin);
  const vec3 tc = u / grids[slot].temperature.dims;
#define TEMPERATURE_LOOKUP(i) textureLod(temperature_tex[i], tc, 0.0).r
  RETURN_GRID_SLOT(slot, TEMPERATURE_LOOKUP)
#undef TEMPERATURE_LOOKUP
}
vec3 blackbody_at(uint slot, float s) {
  if (GRID_COUNT <= 1u) slot = 0u;
#define BLACKBODY_LOOKUP(i) textureLod(blackbody_tex[i], s, 0.0).rgb
  RETURN_GRID_SLOT(slot, BLACKBODY_LOOKUP)
#undef BLACKBODY_LOOKUP
}

vec3 density_texel(uint slot, vec3 p) {
  vec4 p1 = vec4(p, 1.0);
  return vec3(dot(grids[slot].density.row0, p1), dot(grids[slot].density.row1, p1), dot(grids[slot].density.row2, p1));
}
vec3 density_texel_dir(uint slot, vec3 d) {
  vec4 d0 = vec4(d, 0.0);
  return vec3(dot(grids[slot].density.row0, d0), dot(grids[slot].density.row1, d0), dot(grids[slot].density.row2, d0));
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
  const float T = grid_kelvin(value, grids[slot].temperature_offset, grids[slot].temperature_scale);
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

// What the media are at a point, as one record (coefficients_at): σa and σs
// summed over the media present; per medium, rho[i] its density_scale ·
// density (1 for a homogeneous medium; the scattering-lobe choice and the
// emission read it) and temperature_value[i] its temperature grid's value
// where the density lookup reads it (TEMPERATURE_IN_DENSITY; else 0). What
// the path does there (absorb, scatter, null) is the integrator's
// (tracking.glsl path_track).
struct MediumPoint {
  vec3 sigma_a, sigma_s;
  float rho[MEDIA_N];
  float temperature_value[MEDIA_N];
};

// The media at a tentative collision (arrays sized by a specialization
// constant cannot be returned: an out parameter). With `stochastic` and
// STOCHASTIC_DENSITY the grids' densities are stochastic_density's unbiased
// one-texel estimates, and temperature_value is 0 (event_temperatures reads it
// where the path has its event).
void coefficients_at(vec3 x, float t, vec2 span[MEDIA_N], bool stochastic, out MediumPoint mp,
                     inout PathStats stats, inout uint rng) {
  mp.sigma_a = vec3(0.0);
  mp.sigma_s = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    mp.rho[i] = 0.0;
    mp.temperature_value[i] = 0.0;
    if (!(span[i].x <= t && t < span[i].y)) continue;
    GpuMedium m = media[i];
    float r = 1.0;
    if (is_grid(m)) {
      uint slot = m.grid_slot;
      const vec2 v = STOCHASTIC_DENSITY && stochastic ? vec2(stochastic_density(slot, density_texel(slot, x), rng), 0.0)
                                                      : density_at(slot, density_texel(slot, x));
      r = grids[slot].density_scale * v.x;
      mp.temperature_value[i] = v.y;
      stats.lookups += 1.0;
    }
    mp.rho[i] = r;
    mp.sigma_a += r * m.sigma_a;
    mp.sigma_s += r * m.sigma_s;
  }
}

// The temperature values at x that a stochastic coefficients_at left out
// (TEMPERATURE_IN_DENSITY reads them with the density; otherwise grid_le reads
// its own texture): the emission needs the trilinear value, since Le is not
// linear in T.
void event_temperatures(vec3 x, float t, vec2 span[MEDIA_N], inout MediumPoint mp) {
  if (!STOCHASTIC_DENSITY || !TEMPERATURE_IN_DENSITY) return;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].x <= t && t < span[i].y) || !is_grid(media[i])) continue;
    const uint slot = media[i].grid_slot;
    mp.temperature_value[i] = density_at(slot, density_texel(slot, x)).y;
  }
}

// Emitted power per unit length, Σ sigma_a_i(x)·Le_i(x), over the media at t.
vec3 emission_at(vec3 x, float t, vec2 span[MEDIA_N], MediumPoint mp) {
  vec3 E = vec3(0.0);
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    if (!(span[i].x <= t && t < span[i].y)) continue;
    GpuMedium m = media[i];
    if (is_grid(m)) {
      if (mp.rho[i] > 0.0) E += mp.rho[i] * m.sigma_a * grid_le(m, m.grid_slot, x, mp.temperature_value[i]);
    } else {
      E += m.emission;
    }
  }
  return E;
}
