#version 460
// Per-pixel path tracing of emissive participating media (homogeneous spheres
// and boxes), one progressive pass per dispatch. Estimator: the seed's
// "absorption" estimator — a path that is absorbed collects Le; it scatters by
// Henyey–Greenstein; escaping paths see the background.
#extension GL_GOOGLE_include_directive : require

#include "shared/gpu_types.h"
#include "rng.glsl"
#include "sampling.glsl"
#include "geometry.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

layout(std140, set = 0, binding = BINDING_FRAME) uniform FrameBlock { FrameConstants frame; };
layout(std430, set = 0, binding = BINDING_MEDIA) readonly buffer MediaBlock { GpuMedium media[]; };
layout(std430, set = 0, binding = BINDING_ACCUM) buffer AccumBlock { AccumTexel accum[]; };
layout(push_constant) uniform PassBlock { PassConstants pass_constants; };

float avg3(vec3 v) { return (v.x + v.y + v.z) * (1.0 / 3.0); }
float max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

struct PathStats {
  float events;   // real collisions: absorptions + scatterings
  float lookups;  // density texture lookups (none for homogeneous media)
};

// Radiance along one camera ray.
//
// Media are piecewise constant along a ray, so the ray is split at the bounds'
// entry/exit distances and free flights restart at each boundary (memoryless).
// RGB sigma is handled by spectral tracking (Kutz et al. 2017, "Spectral and
// Decomposition Tracking", history-aware averaged probabilities): distances are
// sampled with the grey majorant sigma_bar = max channel of sigma_t, and event x
// (absorb / scatter / null) is chosen with P_x = avg(sigma_x ⊙ w) / (sigma_bar·avg(w));
// the path weight w then picks up sigma_x / (sigma_bar·P_x) per channel. For grey
// media every factor is 1 and this is plain delta tracking.
vec3 trace(vec3 o, vec3 d, inout uint rng, inout PathStats stats) {
  uint medium_count = frame.image.z;
  uint max_depth = frame.image.w;
  vec3 w = vec3(1.0);
  vec3 L = vec3(0.0);
  uint depth = 0u;
  for (;;) {
    // Intervals of every medium along the current ray.
    vec2 span[MAX_MEDIA];
    bool any_ahead = false;
    for (uint i = 0u; i < medium_count; ++i) {
      GpuMedium m = media[i];
      vec2 t;
      bool hit = uint(m.sigma_a.w) == SHAPE_SPHERE
                     ? intersect_sphere(o, d, m.bounds0.xyz, m.bounds0.w, t)
                     : intersect_box(o, d, m.bounds0.xyz, m.bounds1.xyz, t);
      span[i] = hit ? t : vec2(-1.0);
      any_ahead = any_ahead || hit;
    }
    if (!any_ahead) {
      L += w * frame.background.rgb;
      return L;
    }

    bool scattered = false;
    float t = 0.0;
    while (!scattered) {
      // Active media at t and the next boundary beyond t.
      vec3 sigma_a = vec3(0.0), sigma_s = vec3(0.0), emitted = vec3(0.0);
      float t_next = 1.0 / 0.0;
      for (uint i = 0u; i < medium_count; ++i) {
        vec2 s = span[i];
        if (s.y <= t) continue;
        if (s.x > t) { t_next = min(t_next, s.x); continue; }
        t_next = min(t_next, s.y);
        GpuMedium m = media[i];
        sigma_a += m.sigma_a.rgb;
        sigma_s += m.sigma_s.rgb;
        emitted += m.emission.rgb;
      }
      if (isinf(t_next)) {  // left every medium
        L += w * frame.background.rgb;
        return L;
      }
      vec3 sigma_t = sigma_a + sigma_s;
      float sigma_bar = max3(sigma_t);
      if (sigma_bar <= 0.0) { t = t_next; continue; }
      float dt = sample_free_flight(sigma_bar, rng_next(rng));
      if (t + dt >= t_next) { t = t_next; continue; }
      t += dt;

      vec3 sigma_n = vec3(sigma_bar) - sigma_t;
      float w_avg = avg3(w);
      float c = sigma_bar * w_avg;
      float p_a = avg3(sigma_a * w) / c;
      float p_s = avg3(sigma_s * w) / c;
      float u = rng_next(rng);
      if (u < p_a) {
        // Absorbed: collect sigma_a·Le / (sigma_bar·P_a) (Kutz et al. 2017, eq. 20).
        stats.events += 1.0;
        L += w * emitted / (sigma_bar * p_a);
        return L;
      } else if (u < p_a + p_s) {
        stats.events += 1.0;
        if (depth >= max_depth) return L;
        ++depth;
        w *= sigma_s / (sigma_bar * p_s);
        // Phase function of the mixture sum_i (sigma_s_i / sigma_s) p_i: pick medium i
        // with q_i ∝ avg(share_i ⊙ w), sample its HG lobe, weight share_i / q_i.
        vec3 inv_sigma_s = 1.0 / max(sigma_s, vec3(1e-30));
        float total = 0.0;
        for (uint i = 0u; i < medium_count; ++i)
          if (span[i].x <= t && t < span[i].y) total += avg3(media[i].sigma_s.rgb * inv_sigma_s * w);
        float pick = rng_next(rng) * total;
        float acc = 0.0, g = 0.0;
        vec3 mix_w = vec3(0.0);
        for (uint i = 0u; i < medium_count; ++i) {
          if (!(span[i].x <= t && t < span[i].y)) continue;
          vec3 share = media[i].sigma_s.rgb * inv_sigma_s;
          float p_i = avg3(share * w);
          if (p_i <= 0.0) continue;
          acc += p_i;
          g = media[i].sigma_s.w;
          mix_w = share * (total / p_i);
          if (pick < acc) break;
        }
        w *= mix_w;
        o = o + t * d;
        d = sample_hg(d, g, vec2(rng_next(rng), rng_next(rng)));
        scattered = true;
      } else {
        w *= sigma_n / (sigma_bar * (1.0 - p_a - p_s));
      }
      if (max3(w) <= 0.0) return L;
    }
  }
  return L;
}

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  uint width = frame.image.x, height = frame.image.y;
  if (pixel.x >= width || pixel.y >= height) return;
  uint pixel_index = pixel.y * width + pixel.x;

  vec3 pass_sum = vec3(0.0), pass_sq = vec3(0.0);
  PathStats stats = PathStats(0.0, 0.0);
  float nonfinite = 0.0;
  for (uint k = 0u; k < pass_constants.spp; ++k) {
    uint rng = rng_init(frame.sampling.x, frame.sampling.y, pixel_index, pass_constants.sample_offset + k);
    // Box filter: jitter uniformly inside the pixel; pixel (0,0) is top-left.
    vec2 jitter = vec2(rng_next(rng), rng_next(rng));
    vec2 ndc = vec2(2.0 * (float(pixel.x) + jitter.x) / float(width) - 1.0,
                    1.0 - 2.0 * (float(pixel.y) + jitter.y) / float(height));
    float tan_half = frame.camera_position.w, aspect = frame.camera_forward.w;
    vec3 d = normalize(frame.camera_forward.xyz + ndc.x * tan_half * aspect * frame.camera_right.xyz +
                       ndc.y * tan_half * frame.camera_up.xyz);
    vec3 L = trace(frame.camera_position.xyz, d, rng, stats);
    if (any(isnan(L)) || any(isinf(L))) {
      nonfinite += 1.0;
      L = vec3(0.0);
    }
    pass_sum += L;
    pass_sq += L * L;
  }

  // Kahan-compensated accumulation across passes.
  AccumTexel a = accum[pixel_index];
  precise vec4 y = vec4(pass_sum, stats.events) - a.sum_c;
  precise vec4 s = a.sum + y;
  a.sum_c = (s - a.sum) - y;
  a.sum = s;
  precise vec3 y2 = pass_sq - a.sum_sq_c.xyz;
  precise vec3 s2 = a.sum_sq.xyz + y2;
  a.sum_sq_c.xyz = (s2 - a.sum_sq.xyz) - y2;
  a.sum_sq.xyz = s2;
  a.sum_sq.w += stats.lookups;
  a.sum_sq_c.w += nonfinite;
  accum[pixel_index] = a;
}
