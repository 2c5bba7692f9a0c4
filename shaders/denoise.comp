#version 460
// One iteration of the edge-avoiding à-trous wavelet filter (Dammertz et al.
// 2010, "Edge-Avoiding À-Trous Wavelet Transform for fast Global Illumination
// Filtering") with the variance-guided edge-stopping functions of SVGF
// (Schied et al. 2017, "Spatiotemporal Variance-Guided Filtering", eqs. 1-5
// and 8): a 5×5 B3-spline kernel h whose taps lie 2^i pixels apart, each tap q
// weighted by
//   w(p, q) = h(q) · exp(−|l_p − l_q| / (σ_l·sqrt(g(Var l)_p + g(Var l)_q) + ε)
//                     − |z_p − z_q| / (σ_z·|∇z_p|·|p − q| + ε)
//                     − |a_p − a_q| / σ_a) · max(0, n_p·n_q)^σ_n
// and the variance of the luminance filtered along with the colour by the
// squared weights, Var'_p = Σ w² Var_q / (Σ w)², so the next, wider iteration
// stops at what is left of the noise. g is a 3×3 Gaussian (SVGF eq. 5). One
// change to SVGF: the luminance difference is measured against its own
// standard deviation, sqrt(Var_p + Var_q), not p's alone (SVGF's σ_l·sqrt(Var_p)
// with σ_l = 4 is about ours with σ_l = 2.8 where the two agree). The weight is
// then symmetric, so a bright outlier (a firefly) that its neighbours' small
// variances would shut out under SVGF's is spread into them instead of
// dimmed alone: its energy stays in the image (without it, the 16-spp fires
// lost ~2 % of their mean). The host (host/denoise/Denoiser.cpp)
// runs it for i = 0, 1, 2, ...; docs/compositing.md "Denoiser".
// The guided filter (Denoiser::run_guided) runs the same kernel with its own
// weights (DENOISE_GUIDED_FEATURES: relative depth, normalized normals,
// albedo only between surfaces; DENOISE_USE_GUIDE: the guide's relative
// luminance and alpha differences) and one more kind of pass,
// DENOISE_PASS_BLUR: a separable Gaussian, the ratio estimator's window.
#extension GL_GOOGLE_include_directive : require

#include "shared/denoise_types.h"

layout(local_size_x = DENOISE_WORKGROUP_SIZE, local_size_y = DENOISE_WORKGROUP_SIZE) in;

// Storage buffers: the taps are neighbours, so these gathers stay in cache
// (on lavapipe storage-buffer loads are slow when they gather at random, as
// lookups through a volume do, not for neighbouring pixels).
layout(std430, set = 0, binding = DENOISE_BINDING_COLOR_IN) readonly buffer ColorIn { vec4 color_in[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_VAR_IN) readonly buffer VarIn { float var_in[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_COLOR_OUT) writeonly buffer ColorOut { vec4 color_out[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_VAR_OUT) writeonly buffer VarOut { float var_out[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_NORMAL_DEPTH) readonly buffer NormalDepth { vec4 normal_depth[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_ALBEDO_DZ) readonly buffer AlbedoDz { vec4 albedo_dz[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_VAR_BLURRED) buffer VarBlurred { float var_blurred[]; };
layout(std430, set = 0, binding = DENOISE_BINDING_GUIDE) readonly buffer Guide { vec4 guide[]; };
layout(push_constant) uniform DenoiseBlock { DenoiseConstants dc; };

// Rec. 709 / linear sRGB luminance, the l of the edge-stopping function.
float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// A pixel with a surface as its first event: its normal has length ~1 (media
// and misses have 0; a pixel that is half surface, half medium ~0.5).
bool on_surface(vec3 n) { return dot(n, n) > 0.25; }

void main() {
  const ivec2 size = ivec2(dc.size_step_flags.xy);
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  const int step = int(dc.size_step_flags.z);
  const uint flags = dc.size_step_flags.w;
  const float sigma_l = dc.sigmas.x, sigma_n = dc.sigmas.y, sigma_z = dc.sigmas.z, sigma_a = dc.sigmas.w;
  const int ip = p.y * size.x + p.x;


  if ((flags & DENOISE_PASS_BLUR) != 0u) {
    // The ratio estimator's window (host/denoise/Denoiser.cpp): a plain
    // Gaussian, separable, with the taps that fall outside the image left out.
    const float s = dc.guide_sigmas.w;
    const int r = int(ceil(2.0 * s));
    const ivec2 axis = step == 1 ? ivec2(1, 0) : ivec2(0, 1);
    vec4 sum = vec4(0.0);
    float wsum = 0.0;
    for (int j = -r; j <= r; ++j) {
      const ivec2 q = p + j * axis;
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      const float w = exp(-0.5 * float(j * j) / (s * s));
      sum += w * color_in[q.y * size.x + q.x];
      wsum += w;
    }
    color_out[ip] = sum / wsum;
    return;
  }

  if ((flags & DENOISE_PASS_PREFILTER) != 0u) {
    // SVGF eq. 5: the luminance variance under a 3×3 Gaussian, so that one
    // pixel's noisy variance estimate does not decide its edges alone.
    float var_g = 0.0, g_sum = 0.0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const ivec2 q = p + ivec2(dx, dy);
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
        const float g = (dx == 0 ? 0.5 : 0.25) * (dy == 0 ? 0.5 : 0.25);
        var_g += g * var_in[q.y * size.x + q.x];
        g_sum += g;
      }
    var_blurred[ip] = max(var_g / g_sum, 0.0);
    return;
  }

  const vec4 cp = color_in[ip];
  const float lp = luminance(cp.rgb);
  const float var_p = var_blurred[ip];

  const bool use_nz = (flags & DENOISE_USE_NORMAL_DEPTH) != 0u, use_a = (flags & DENOISE_USE_ALBEDO) != 0u;
  const bool use_guide = (flags & DENOISE_USE_GUIDE) != 0u, guided_features = (flags & DENOISE_GUIDED_FEATURES) != 0u;
  vec4 nz_p = vec4(0.0), a_p = vec4(0.0), g_p = vec4(0.0);
  if (use_nz || use_a) nz_p = normal_depth[ip], a_p = albedo_dz[ip];
  if (use_guide) g_p = guide[ip];
  const float guide_l_p = luminance(g_p.rgb);
  const bool surface_p = use_nz && on_surface(nz_p.xyz);
  if (((flags & DENOISE_ONLY_SURFACES) != 0u && !surface_p) ||
      ((flags & DENOISE_SKIP_EMPTY) != 0u && cp == vec4(0.0) && g_p.a == 0.0)) {
    color_out[ip] = cp;
    var_out[ip] = var_in[ip];
    return;
  }

  // B3 spline (1/16, 1/4, 3/8, 1/4, 1/16) scaled to 1 at the centre; the
  // centre tap has weight 1.
  const float h[3] = float[3](1.0, 2.0 / 3.0, 1.0 / 6.0);
  vec4 sum_c = cp;
  float sum_w = 1.0, sum_v = var_in[ip];
  for (int yy = -2; yy <= 2; ++yy)
    for (int xx = -2; xx <= 2; ++xx) {
      if (xx == 0 && yy == 0) continue;
      const ivec2 q = p + ivec2(xx, yy) * step;
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      const int iq = q.y * size.x + q.x;
      const vec4 cq = color_in[iq];
      // SVGF eq. 4, against the standard deviation of the difference.
      float e = abs(lp - luminance(cq.rgb)) / (sigma_l * sqrt(var_p + var_blurred[iq]) + 1e-10);
      float wn = 1.0;
      if (use_nz || use_a) {
        if (use_nz) {
          // Normals and depth only between two surface pixels: a medium's
          // depth is a random free-flight distance, not a feature.
          const vec4 nz_q = normal_depth[iq];
          const bool surface_q = on_surface(nz_q.xyz);
          if (surface_p && surface_q && guided_features) {
            wn = pow(max(0.0, dot(normalize(nz_p.xyz), normalize(nz_q.xyz))), sigma_n);
            e += abs(nz_p.w - nz_q.w) / (sigma_z * (nz_p.w + nz_q.w) + 1e-6);
          } else if (surface_p && surface_q) {
            wn = pow(max(0.0, dot(nz_p.xyz, nz_q.xyz)), sigma_n);  // SVGF eq. 3
            e += abs(nz_p.w - nz_q.w) / (sigma_z * a_p.w * float(step) * length(vec2(xx, yy)) + 1e-3);  // SVGF eq. 2
          } else if (surface_p != surface_q) {
            wn = 0.0;  // a surface's silhouette against a medium or the background
          }
        }
        if (use_a && (!guided_features || (surface_p && on_surface(normal_depth[iq].xyz))))
          e += length(a_p.rgb - albedo_dz[iq].rgb) / sigma_a;
      }
      if (use_guide) {
        // The guide's relative difference, with a floor τ_g where it is dark,
        // and its alpha's difference.
        const vec4 g_q = guide[iq];
        const float guide_l_q = luminance(g_q.rgb);
        e += abs(guide_l_p - guide_l_q) / (dc.guide_sigmas.x * (guide_l_p + guide_l_q) + dc.guide_sigmas.y) +
             abs(g_p.a - g_q.a) / dc.guide_sigmas.z;
      }
      const float w = h[abs(xx)] * h[abs(yy)] * wn * exp(-e);
      sum_c += w * cq;
      sum_w += w;
      sum_v += w * w * var_in[iq];
    }
  color_out[ip] = sum_c / sum_w;
  var_out[ip] = sum_v / (sum_w * sum_w);  // SVGF eq. 8 (Var of a weighted mean)
}
