// Light sampling: the environment map and the emission CDF of an emissive grid
// medium. The GLSL twin of host/light/EnvironmentMap and host/light/EmissionCdf:
// same names, same argument order, the same searches over the same float CDFs,
// so the same uniforms give the same samples (docs/lights.md).
//
// Contract with the includer. Include shared/light_types.h, then define what
// you use, then include this file:
//
//   #define LIGHTS_ENVIRONMENT   // env_radiance / env_sample / env_pdf, needs:
//     layout(std430, binding = …) readonly buffer EnvTexelBlock { vec4 env_texels[]; };
//     layout(std430, binding = …) readonly buffer EnvCdfBlock { float env_cdf[]; };
//   #define LIGHTS_EMISSION      // emission_sample / emission_pdf / emission_direction_pdf, needs:
//     layout(std430, binding = …) readonly buffer EmissionCdfBlock { float emission_cdf[]; };
//     layout(std430, binding = …) readonly buffer EmissionCellBlock { uint emission_cells[]; };
//     layout(std430, binding = …) readonly buffer EmissionPmfBlock { float emission_pmf[]; };
//     layout(std430, binding = …) readonly buffer EmissionClusterBlock { GpuEmissionCluster emission_clusters[]; };
//
// The GpuEnvironment / GpuEmissionCdf headers are passed by value (keep them in
// a uniform block). Block names are free; the array names are the contract.
#ifndef PYROLUME_LIGHTS_GLSL
#define PYROLUME_LIGHTS_GLSL

const float LIGHTS_PI = 3.14159265358979;

#ifdef LIGHTS_ENVIRONMENT

struct EnvSample {
  vec3 dir;       // unit, world space, away from the scene
  float pdf;      // solid angle (1/sr); 0: no sample
  vec3 radiance;  // scale included
};

// Map (u, v) of a world direction: Rz(−rotation)·d (after Rx(90°), d.x, −d.z,
// d.y, in a Y-up scene), then u = 0.5 − φ/2π, v = θ/π.
vec2 env_direction_to_uv(GpuEnvironment env, vec3 world_d) {
  vec3 d = env.zenith_y != 0u ? vec3(world_d.x, -world_d.z, world_d.y) : world_d;
  float c = env.cos_rotation, s = env.sin_rotation;
  float x = c * d.x + s * d.y;
  float y = -s * d.x + c * d.y;
  float cos_theta = clamp(d.z / length(d), -1.0, 1.0);
  float u = 0.5 - atan(y, x) * (0.5 / LIGHTS_PI);
  u = u >= 1.0 ? u - 1.0 : (u < 0.0 ? u + 1.0 : u);
  return vec2(u, acos(cos_theta) * (1.0 / LIGHTS_PI));
}

// θ = π·v, φ = π − 2π·u, then Rz(rotation).
vec3 env_uv_to_direction(GpuEnvironment env, vec2 uv) {
  float theta = LIGHTS_PI * uv.y, phi = LIGHTS_PI - 2.0 * LIGHTS_PI * uv.x;
  float st = sin(theta);
  float x = st * cos(phi), y = st * sin(phi);
  float c = env.cos_rotation, s = env.sin_rotation;
  vec3 d = vec3(c * x - s * y, s * x + c * y, cos(theta));
  return env.zenith_y != 0u ? vec3(d.x, d.z, -d.y) : d;  // Rx(−90°) back to a Y-up world
}

// Bilinear between texel centres, wrapping in u, clamping in v (no scale).
vec3 env_lookup_uv(GpuEnvironment env, vec2 uv) {
  int W = int(env.width), H = int(env.height);
  float x = uv.x * float(W) - 0.5, y = uv.y * float(H) - 0.5;
  float x0 = floor(x), y0 = floor(y);
  float fx = x - x0, fy = y - y0;
  int i0 = int(x0) % W;  // GLSL % of a negative int is undefined: wrap by hand
  if (int(x0) < 0) i0 = W - 1;
  int i1 = i0 + 1 >= W ? 0 : i0 + 1;
  int j0 = clamp(int(y0), 0, H - 1), j1 = clamp(int(y0) + 1, 0, H - 1);
  vec3 a = env_texels[j0 * W + i0].rgb, b = env_texels[j0 * W + i1].rgb;
  vec3 c = env_texels[j1 * W + i0].rgb, d = env_texels[j1 * W + i1].rgb;
  return mix(mix(a, b, fx), mix(c, d, fx), fy);
}

vec3 env_radiance(GpuEnvironment env, vec3 dir) {
  return env.scale * env_lookup_uv(env, env_direction_to_uv(env, dir));
}

// The largest i in [0, n) with env_cdf[base + i] <= u, and u's place inside the
// bin (host/light/PiecewiseConstant.h sample_cdf).
uint env_sample_cdf(uint base, uint n, float u, out float offset) {
  uint lo = 0u, hi = n - 1u;
  while (lo < hi) {
    uint mid = (lo + hi + 1u) / 2u;
    if (env_cdf[base + mid] <= u) lo = mid; else hi = mid - 1u;
  }
  float a = env_cdf[base + lo], b = env_cdf[base + lo + 1u];
  offset = b > a ? clamp((u - a) / (b - a), 0.0, 0.99999994) : 0.0;
  return lo;
}

// Solid-angle pdf = p_uv / (2π² sinθ), p_uv the texel's piecewise-constant density.
EnvSample env_sample(GpuEnvironment env, vec2 u2) {
  EnvSample s;
  s.dir = vec3(0.0, 0.0, 1.0);
  s.pdf = 0.0;
  s.radiance = vec3(0.0);
  if (env.can_sample == 0u) return s;
  uint W = env.width, H = env.height;
  float dv, du;
  uint j = env_sample_cdf(0u, H, u2.y, dv);
  uint i = env_sample_cdf((H + 1u) + j * (W + 1u), W, u2.x, du);
  vec2 uv = vec2((float(i) + du) / float(W), (float(j) + dv) / float(H));
  float sin_theta = sin(LIGHTS_PI * uv.y);
  if (!(sin_theta > 0.0)) return s;
  s.dir = env_uv_to_direction(env, uv);
  s.pdf = env_texels[j * W + i].w / (2.0 * LIGHTS_PI * LIGHTS_PI * sin_theta);
  s.radiance = env.scale * env_lookup_uv(env, uv);
  return s;
}

float env_pdf(GpuEnvironment env, vec3 dir) {
  if (env.can_sample == 0u) return 0.0;
  vec2 uv = env_direction_to_uv(env, dir);
  float sin_theta = sin(LIGHTS_PI * uv.y);
  if (!(sin_theta > 0.0)) return 0.0;
  uint W = env.width, H = env.height;
  uint i = min(uint(uv.x * float(W)), W - 1u), j = min(uint(uv.y * float(H)), H - 1u);
  return env_texels[j * W + i].w / (2.0 * LIGHTS_PI * LIGHTS_PI * sin_theta);
}

#endif  // LIGHTS_ENVIRONMENT

#ifdef LIGHTS_EMISSION

struct EmissionSample {
  vec3 p;     // world space
  float pdf;  // VOLUME measure (1/unit³); from x in solid angle: pdf·|p − x|² (no cosine)
  uint cell;  // linear cell index; 0xffffffff: no sample
};

// I_s(o) of cluster s (absolute index): its share of the emission over the
// squared distance from o, bounded by its radius (EmissionCdf::cluster_importance).
float emission_cluster_importance(uint s, vec3 o) {
  vec3 d = o - emission_clusters[s].center;
  return emission_clusters[s].power / max(dot(d, d), emission_clusters[s].radius_sq);
}

// The absolute index of the first of the copies of the nonempty clusters
// (after the grid of clusters; EmissionCdf::gpu_clusters).
uint emission_nonempty_clusters(GpuEmissionCdf e) { return e.first_cluster + e.clusters.x * e.clusters.y * e.clusters.z; }

// Σ_s I_s(o): the normaliser of the distribution seen from o; one per vertex,
// passed to the functions below as `norm`.
float emission_receiver_norm(GpuEmissionCdf e, vec3 o) {
  if (e.entry_count == 0u) return 0.0;
  float z = 0.0;
  const uint first = emission_nonempty_clusters(e);
  for (uint s = 0u; s < e.nonempty_clusters; ++s) z += emission_cluster_importance(first + s, o);
  return z;
}

// The cluster of a cell; inv_k = 1/k. (cell + 0.5)/k is at least 1/(2k) from
// an integer, far more than float rounding, so the float product is exact
// after floor, and it avoids an integer division (scalarised on llvmpipe).
uint emission_cluster_of(GpuEmissionCdf e, uvec3 cell, float inv_k) {
  uvec3 c = uvec3((vec3(cell) + 0.5) * inv_k);
  return e.first_cluster + (c.z * e.clusters.y + c.y) * e.clusters.x + c.x;
}

// From receiver o: a cluster by I_s(o) (the first whose running sum exceeds
// u·norm; the last nonempty one if rounding leaves none), then u_cell picks
// the cell by the cluster's inclusive CDF (its own number: u rescaled inside
// the cluster would lose float precision in small clusters), then a uniform
// point in the cell's world-space parallelepiped (EmissionCdf::sample_from).
EmissionSample emission_sample(GpuEmissionCdf e, vec3 o, float norm, float u, float u_cell, vec3 u3) {
  EmissionSample s;
  s.p = vec3(0.0);
  s.pdf = 0.0;
  s.cell = 0xffffffffu;
  if (e.entry_count == 0u || !(norm > 0.0)) return s;
  float target = u * norm, acc = 0.0, share = 0.0;
  uint pick = 0xffffffffu;
  const uint first = emission_nonempty_clusters(e);
  for (uint k = 0u; k < e.nonempty_clusters; ++k) {
    uint c = first + k;
    float i = emission_cluster_importance(c, o);
    pick = c;
    share = i;
    acc += i;
    if (target < acc) break;
  }
  if (pick == 0xffffffffu || !(share > 0.0)) return s;
  uint base = e.first_entry;
  uint lo = emission_clusters[pick].first_entry, hi = lo + emission_clusters[pick].entry_count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (emission_cdf[base + mid] <= u_cell) lo = mid + 1u; else hi = mid;
  }
  uint cell = emission_cells[base + lo];
  uint X = e.cells.x, Y = e.cells.y;
  vec4 c1 = vec4(float(cell % X) + u3.x, float((cell / X) % Y) + u3.y, float(cell / (X * Y)) + u3.z, 1.0);
  s.p = vec3(dot(e.cell_to_world_row0, c1), dot(e.cell_to_world_row1, c1), dot(e.cell_to_world_row2, c1));
  s.pdf = share / norm * emission_pmf[e.first_cell + cell] * e.inv_cell_volume;
  s.cell = cell;
  return s;
}

// Volume pdf from receiver o of the cell containing world point p (0 outside
// the grid's cells).
float emission_pdf(GpuEmissionCdf e, vec3 o, float norm, vec3 p) {
  if (e.entry_count == 0u || !(norm > 0.0)) return 0.0;
  vec4 p1 = vec4(p, 1.0);
  vec3 c = floor(vec3(dot(e.world_to_cell_row0, p1), dot(e.world_to_cell_row1, p1), dot(e.world_to_cell_row2, p1)));
  if (any(lessThan(c, vec3(0.0))) || any(greaterThanEqual(c, vec3(e.cells)))) return 0.0;
  uvec3 ci = uvec3(c);
  uint cell = (ci.z * e.cells.y + ci.y) * e.cells.x + ci.x;
  float q = emission_pmf[e.first_cell + cell];
  if (!(q > 0.0)) return 0.0;
  return emission_cluster_importance(emission_cluster_of(e, ci, 1.0 / float(e.cluster_k)), o) / norm * q * e.inv_cell_volume;
}

// Solid-angle pdf at o of direction w (unit) toward a point drawn by
// emission_sample from o: ∫₀^∞ pdf(o + t·w) t² dt over the cells the ray
// crosses, by 3D DDA (Amanatides & Woo 1987); EmissionCdf::direction_pdf on
// the host. The map to cell coordinates is affine, so t stays the world
// distance there.
float emission_direction_pdf(GpuEmissionCdf e, vec3 o, float norm, vec3 w) {
  if (e.entry_count == 0u || !(norm > 0.0)) return 0.0;
  vec4 o1 = vec4(o, 1.0), w0 = vec4(w, 0.0);
  vec3 co = vec3(dot(e.world_to_cell_row0, o1), dot(e.world_to_cell_row1, o1), dot(e.world_to_cell_row2, o1));
  vec3 cw = vec3(dot(e.world_to_cell_row0, w0), dot(e.world_to_cell_row1, w0), dot(e.world_to_cell_row2, w0));
  ivec3 n = ivec3(e.cells);
  const float BIG = 3.0e38;
  float t0 = 0.0, t1 = BIG;
  vec3 t_next = vec3(BIG), t_delta = vec3(BIG);
  for (int a = 0; a < 3; ++a) {
    if (cw[a] == 0.0) {
      if (co[a] < 0.0 || co[a] >= float(n[a])) return 0.0;
      continue;
    }
    float ta = -co[a] / cw[a], tb = (float(n[a]) - co[a]) / cw[a];
    t0 = max(t0, min(ta, tb));
    t1 = min(t1, max(ta, tb));
  }
  if (!(t0 < t1)) return 0.0;
  ivec3 cell = clamp(ivec3(floor(co + cw * t0)), ivec3(0), n - 1);
  ivec3 stp = ivec3(0);
  for (int a = 0; a < 3; ++a) {
    if (cw[a] > 0.0) {
      stp[a] = 1;
      t_next[a] = (float(cell[a] + 1) - co[a]) / cw[a];
      t_delta[a] = 1.0 / cw[a];
    } else if (cw[a] < 0.0) {
      stp[a] = -1;
      t_next[a] = (float(cell[a]) - co[a]) / cw[a];
      t_delta[a] = -1.0 / cw[a];
    }
  }
  float sum = 0.0, t = t0, importance = 0.0;
  uint last = 0xffffffffu;
  const float inv_k = 1.0 / float(e.cluster_k);
  // At most one step per cell face crossed: n.x + n.y + n.z.
  for (int k = 0; k < n.x + n.y + n.z && t < t1; ++k) {
    int a = t_next.x <= t_next.y ? (t_next.x <= t_next.z ? 0 : 2) : (t_next.y <= t_next.z ? 1 : 2);
    float tb = min(t_next[a], t1);
    float q = emission_pmf[e.first_cell + uint((cell.z * n.y + cell.y) * n.x + cell.x)];
    if (q > 0.0) {
      uint s = emission_cluster_of(e, uvec3(cell), inv_k);
      if (s != last) {
        importance = emission_cluster_importance(s, o);
        last = s;
      }
      sum += importance * q * (tb - t) * (tb * tb + tb * t + t * t);  // tb³ − t³, factored
    }
    t = tb;
    cell[a] += stp[a];
    if (cell[a] < 0 || cell[a] >= n[a]) break;
    t_next[a] += t_delta[a];
  }
  return sum * e.inv_cell_volume * (1.0 / 3.0) / norm;
}

#endif  // LIGHTS_EMISSION

#endif  // PYROLUME_LIGHTS_GLSL
