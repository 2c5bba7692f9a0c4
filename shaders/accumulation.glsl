// A pass's samples into the pixel's accumulation (AccumTexel), Kahan-compensated.
// One Kahan (1965) summation step: s − c carries the sum of the x's to about
// twice float precision (`precise` stops the compiler reassociating). Used for
// the samples within a pass (64 float additions lose up to ~2e-6 otherwise)
// and for the passes in the accumulation buffer.
void kahan_add(inout vec3 s, inout vec3 c, vec3 x) {
  precise vec3 y = x - c;
  precise vec3 t = s + y;
  c = (t - s) - y;
  s = t;
}

// Whether a sample's radiance is recorded as it is: NaN, Inf and beyond
// MAX_SAMPLE_RADIANCE fail the comparison (add_sample records 0 instead).
bool recorded_radiance(vec3 L) { return all(lessThanEqual(abs(L), vec3(MAX_SAMPLE_RADIANCE))); }

// One sample's radiance and alpha into the pass's sums (NaN and Inf fail the
// comparison too: counted, and recorded as 0; alpha as 1). The pass's alpha
// sums (Σα, Σα²) are plain: α is at most ~1 and a pass is short.
void add_sample(vec3 L, float alpha, inout vec3 pass_sum, inout vec3 pass_sum_c, inout vec3 pass_sq,
                inout vec3 pass_sq_c, inout vec2 pass_alpha, inout float nonfinite) {
  if (!recorded_radiance(L)) {
    nonfinite += 1.0;
    L = vec3(0.0);
  }
  if (!(abs(alpha) <= MAX_SAMPLE_RADIANCE)) alpha = 1.0;
  kahan_add(pass_sum, pass_sum_c, L);
  kahan_add(pass_sq, pass_sq_c, L * L);
  pass_alpha += vec2(alpha, alpha * alpha);
}

// A pass's sums into the pixel's accumulation, Kahan-compensated across passes.
void add_pass(uint pixel_index, vec3 pass_sum, vec3 pass_sum_c, vec3 pass_sq, vec3 pass_sq_c, vec2 pass_alpha,
              PathStats stats, float nonfinite) {
  AccumTexel a = accum[pixel_index];
  precise vec4 y = vec4(pass_sum - pass_sum_c, stats.events) - vec4(a.sum_c, a.events_c);
  precise vec4 s = vec4(a.sum, a.events) + y;
  const vec4 c = (s - vec4(a.sum, a.events)) - y;
  a.sum_c = c.xyz;
  a.events_c = c.w;
  a.sum = s.xyz;
  a.events = s.w;
  precise vec3 y2 = (pass_sq - pass_sq_c) - a.sum_sq_c;
  precise vec3 s2 = a.sum_sq + y2;
  a.sum_sq_c = (s2 - a.sum_sq) - y2;
  a.sum_sq = s2;
  a.lookups += stats.lookups;
  a.nonfinite += nonfinite;
  accum[pixel_index] = a;
  AlphaTexel al = alpha_accum[pixel_index];
  precise vec2 ya = pass_alpha - vec2(al.sum_c, al.sq_c);
  precise vec2 sa = vec2(al.sum, al.sq) + ya;
  const vec2 ca = (sa - vec2(al.sum, al.sq)) - ya;
  alpha_accum[pixel_index] = AlphaTexel(sa.x, ca.x, sa.y, ca.y);
}


// film.aovs (docs/compositing.md "AOVs"): a pass's sums of the light layers
// and of the first-event features, and the pixel's guide (the first pass's
// only; 0 in the others).
struct AovSums {
  vec3 emission, scatter, surface, background;
  vec3 albedo, normal;
  float depth, hits;
  vec3 guide;
  float guide_alpha;
};

AovSums no_aovs() {
  return AovSums(vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), 0.0, 0.0, vec3(0.0), 0.0);
}

// The pixel's guide (guide.glsl's march), once per render, in its first
// pass: a quadrature of the pixel's box filter whose cost does not grow with
// the sample count (docs/compositing.md "The guide"). The 2D Simpson-like rule
//   G = 2/3·g(centre) + 1/12·Σ g(corners)
// cancels the second-order error terms of both the midpoint rule and the
// four-corner trapezoid rule (−(g_xx + g_yy)/24 and +(g_xx + g_yy)/12 of the
// pixel's area): the denoised error within 4 % of four quarter centres'
// (measured), and a corner is shared by four pixels. A pipeline of its own
// (guide.comp) marches every corner and centre once before the first pass, so
// a pixel costs about two marches, no lane waits at a barrier, and the paths'
// pipeline holds no march.
void add_pixel_guide(uvec2 pixel, inout AovSums a) {
  const vec4 corners = guide_points[guide_corner_index(pixel)] + guide_points[guide_corner_index(pixel + uvec2(1u, 0u))] +
                       guide_points[guide_corner_index(pixel + uvec2(0u, 1u))] +
                       guide_points[guide_corner_index(pixel + uvec2(1u, 1u))];
  const vec4 centre = guide_points[guide_centre_index(pixel)];
  const vec4 g = (2.0 / 3.0) * centre + (1.0 / 12.0) * corners;
  a.guide += g.rgb;
  a.guide_alpha += g.a;
}

// One finished sample into the pass's AOV sums. The layers split p.L at the
// path's first vertex (L_first) and take out what the camera ray saw of the
// background (L_direct), so they add up to p.L; a sample that add_sample
// records as 0 (not finite) adds 0 to every layer.
void add_sample_aovs(inout PathState p, inout AovSums a) {
  if (recorded_radiance(p.L)) {
    const vec3 before = p.first_vertex == AOV_VERTEX_NONE ? p.L : p.L_first;
    a.emission += before - p.L_direct;
    a.background += p.L_direct;
    if (p.first_vertex == AOV_VERTEX_SURFACE) a.surface += p.L - before;
    else a.scatter += p.L - before;
  }
  if (p.has_feature) {
    a.albedo += p.feature_albedo;
    a.normal += p.feature_normal;
    a.depth += p.feature_depth;
    a.hits += 1.0;
  }
}

// A pass's AOV sums into the pixel's (plain float sums: AovLightTexel).
void add_pass_aovs(uint pixel_index, AovSums a) {
  AovLightTexel l = aov_lights[pixel_index];
  l.emission += a.emission;
  l.scatter += a.scatter;
  l.surface += a.surface;
  l.background += a.background;
  aov_lights[pixel_index] = l;
  AovFeatureTexel f = aov_features[pixel_index];
  f.albedo += a.albedo;
  f.normal += a.normal;
  f.depth += a.depth;
  f.hits += a.hits;
  f.guide += a.guide;
  f.guide_alpha += a.guide_alpha;
  aov_features[pixel_index] = f;
}
