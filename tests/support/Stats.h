#pragma once
// Statistical comparison of Monte Carlo renders (header-only, reused by the CPU,
// Vulkan and CPU-vs-Vulkan tests). docs/testing.md: per-pixel z-scores with
// the render's own standard errors (accept when >= 99.75 % lie within 4σ, the
// Mitsuba 3 convention), plus the whole-image mean bias
//   bias = (ΣA − ΣB)/ΣB,  SE_bias = sqrt(Σse_A² + Σse_B²)/|ΣB|,
// passing when |bias| < max(tolerance, 4·SE_bias), and informative only when
// SE_bias <= tolerance/2. Also a chi-square goodness-of-fit test for samplers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/Render.h"

namespace pyrolume::test {

// Per pixel-channel mean and standard error of the mean, interleaved RGB.
struct PixelStats {
  int width = 0, height = 0, n = 0;
  std::vector<double> mean, se;
  bool pooled = false;
};

// Below this relative size a sample variance is floating-point cancellation in
// Σx² − n·mean² (identical samples), not noise: treat it as exactly 0.
inline constexpr double kZeroVarianceRel = 1e-12;

// |v − ref| / |ref|: a computed value against a published or closed-form one.
inline double relative_error(double v, double ref) { return std::abs(v - ref) / std::abs(ref); }

// Sample variance of one pixel-channel from its sum and sum of squares:
//   s² = (Σx² − n·mean²)/(n − 1)   (n − 1 degrees of freedom)
inline double sample_variance(double sum, double sum_sq, int n) {
  if (n < 2) return 0.0;
  double mean = sum / n;
  double s2 = (sum_sq - sum * mean) / (n - 1);
  if (!(s2 > kZeroVarianceRel * mean * mean)) return 0.0;
  return s2;
}

// The variance of the *mean* is s²/n, so SE = sqrt(s²/n).
//
// pool3x3: a per-pixel s² from n samples has n − 1 dof and, for Bernoulli-like
// samples (the absorption estimator returns Le or the background), a pixel with
// few hits can show s² ≈ 0 by chance (silhouette pixels). Pooling averages s²
// over the pixel's 3×3 neighbourhood (clipped at the image border); we then use
// max(own s², pooled s²) so that pooling can only widen, never shrink, a pixel's
// error bar next to low-variance neighbours (e.g. background). Conservative:
// power to find bias comes from the bias test and the 99.75 % fraction.
inline PixelStats pixel_stats(const RenderResult& r, bool pool3x3 = false) {
  PixelStats ps;
  ps.width = r.width;
  ps.height = r.height;
  ps.n = r.spp;
  ps.pooled = pool3x3;
  const size_t N = size_t(r.width) * r.height * 3;
  ps.mean.assign(N, 0.0);
  ps.se.assign(N, 0.0);
  if (r.spp <= 0 || r.sum.size() != N || r.sum_sq.size() != N) return ps;
  std::vector<double> var(N);
  for (size_t i = 0; i < N; ++i) {
    ps.mean[i] = r.sum[i] / r.spp;
    var[i] = sample_variance(r.sum[i], r.sum_sq[i], r.spp);
  }
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x)
      for (int c = 0; c < 3; ++c) {
        size_t i = (size_t(y) * r.width + x) * 3 + c;
        double v = var[i];
        if (pool3x3) {
          double acc = 0.0;
          int k = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              int xx = x + dx, yy = y + dy;
              if (xx < 0 || yy < 0 || xx >= r.width || yy >= r.height) continue;
              acc += var[(size_t(yy) * r.width + xx) * 3 + c];
              ++k;
            }
          v = std::max(v, acc / k);
        }
        ps.se[i] = std::sqrt(v / r.spp);
      }
  return ps;
}

struct ZTestOptions {
  double z_limit = 4.0;
  double min_fraction = 0.9975;   // of pixel-channels within z_limit
  double bias_tolerance = 0.005;  // relative
  bool pool3x3 = false;
  int min_spp = 64;         // unpooled: n − 1 dof must make a 4σ test meaningful
  int min_spp_pooled = 8;   // pooled: ~9(n − 1) dof
  double zero_se_rel_tol = 1e-6;  // pixels with SE = 0 must agree this closely
  bool require_informative = true;  // fail when SE_bias > tolerance/2
};

struct ZTestReport {
  size_t channels = 0, within = 0, zero_se_mismatches = 0;
  double fraction = 0.0;
  double bias = 0.0, se_bias = 0.0;
  double bias_rgb[3] = {0, 0, 0}, se_bias_rgb[3] = {0, 0, 0};  // per channel, informational
  double worst_z = 0.0;
  int worst_x = -1, worst_y = -1, worst_c = -1;
  double worst_a = 0.0, worst_b = 0.0, worst_se = 0.0;
  int spp_a = 0, spp_b = 0;
  bool pooled = false;
  double z_limit = 4.0, min_fraction = 0.9975, bias_tolerance = 0.005;
  bool fraction_ok = false, bias_ok = false, informative = false, ok = false;
  std::string problem;  // set when the test could not be run as asked

  std::string summary() const {
    char buf[1024];
    if (!problem.empty()) return "z-test not run: " + problem;
    std::snprintf(buf, sizeof buf,
                  "%s: %zu/%zu pixel-channels within %.1fσ (%.3f %%, need %.2f %%%s)%s; "
                  "bias %+.4f %% ± %.4f %% (SE), tolerance %.2f %%%s [r %+.3f±%.3f g %+.3f±%.3f b %+.3f±%.3f %%]; "
                  "worst |z| %.2f at (x %d, y %d, %c): %.6g vs %.6g, SE %.3g; spp %d vs %d%s",
                  ok ? "PASS" : "FAIL", within, channels, z_limit, 100.0 * fraction, 100.0 * min_fraction,
                  fraction_ok ? "" : ": FAILED", zero_se_mismatches ? " (incl. SE=0 mismatches)" : "",
                  100.0 * bias, 100.0 * se_bias, 100.0 * bias_tolerance,
                  !bias_ok ? ": FAILED" : (!informative ? ": UNINFORMATIVE, SE_bias > tolerance/2: raise spp" : ""),
                  100.0 * bias_rgb[0], 100.0 * se_bias_rgb[0], 100.0 * bias_rgb[1], 100.0 * se_bias_rgb[1],
                  100.0 * bias_rgb[2], 100.0 * se_bias_rgb[2], worst_z, worst_x, worst_y,
                  worst_c >= 0 ? "rgb"[worst_c] : '-', worst_a, worst_b, worst_se, spp_a, spp_b,
                  pooled ? ", variance pooled 3x3" : "");
    std::string s = buf;
    if (zero_se_mismatches) s += "; " + std::to_string(zero_se_mismatches) + " pixel-channels with SE = 0 differ";
    return s;
  }
};

namespace detail {

// Shared core: a = test image (mean, se), b = reference (mean, se; se may be all 0).
inline ZTestReport ztest_core(const PixelStats& a, const std::vector<double>& a_se_raw, const PixelStats& b,
                              const std::vector<double>& b_se_raw, const ZTestOptions& o) {
  ZTestReport rep;
  rep.spp_a = a.n;
  rep.spp_b = b.n;
  rep.pooled = o.pool3x3;
  rep.z_limit = o.z_limit;
  rep.min_fraction = o.min_fraction;
  rep.bias_tolerance = o.bias_tolerance;
  const size_t N = a.mean.size();
  rep.channels = N;
  double sum_a = 0, sum_b = 0, var_sum = 0;
  double sum_a_c[3] = {0, 0, 0}, sum_b_c[3] = {0, 0, 0}, var_c[3] = {0, 0, 0};
  for (size_t i = 0; i < N; ++i) {
    double va = a.mean[i], vb = b.mean[i];
    double se = std::sqrt(a.se[i] * a.se[i] + b.se[i] * b.se[i]);
    double diff = va - vb;
    double z;
    bool pass;
    if (se > 0.0) {
      z = diff / se;
      pass = std::abs(z) <= o.z_limit;
    } else {
      pass = std::abs(diff) <= o.zero_se_rel_tol * std::max(std::abs(va), std::abs(vb));
      z = pass ? 0.0 : std::numeric_limits<double>::infinity();
      if (!pass) ++rep.zero_se_mismatches;
    }
    if (!std::isfinite(va) || !std::isfinite(vb)) {
      pass = false;
      z = std::numeric_limits<double>::infinity();
    }
    if (pass) ++rep.within;
    if (!(std::abs(z) <= rep.worst_z)) {
      rep.worst_z = std::abs(z);
      size_t p = i / 3;
      rep.worst_x = int(p % size_t(a.width));
      rep.worst_y = int(p / size_t(a.width));
      rep.worst_c = int(i % 3);
      rep.worst_a = va;
      rep.worst_b = vb;
      rep.worst_se = se;
    }
    // The bias uses the unpooled SE: a sum over many pixels has plenty of dof.
    double v = a_se_raw[i] * a_se_raw[i] + b_se_raw[i] * b_se_raw[i];
    sum_a += va;
    sum_b += vb;
    var_sum += v;
    sum_a_c[i % 3] += va;
    sum_b_c[i % 3] += vb;
    var_c[i % 3] += v;
  }
  auto rel = [](double sa, double sb) {
    if (sb != 0.0) return (sa - sb) / sb;
    return sa == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  };
  auto rel_se = [](double var, double sb) {
    if (sb != 0.0) return std::sqrt(var) / std::abs(sb);
    return var == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  };
  rep.bias = rel(sum_a, sum_b);
  rep.se_bias = rel_se(var_sum, sum_b);
  for (int c = 0; c < 3; ++c) {
    rep.bias_rgb[c] = rel(sum_a_c[c], sum_b_c[c]);
    rep.se_bias_rgb[c] = rel_se(var_c[c], sum_b_c[c]);
  }
  rep.fraction = N ? double(rep.within) / double(N) : 0.0;
  rep.fraction_ok = N > 0 && rep.fraction >= o.min_fraction;
  rep.bias_ok = std::abs(rep.bias) < std::max(o.bias_tolerance, 4.0 * rep.se_bias);
  rep.informative = rep.se_bias <= 0.5 * o.bias_tolerance;
  rep.ok = rep.fraction_ok && rep.bias_ok && (rep.informative || !o.require_informative);
  return rep;
}

inline std::string check_spp(int n, const ZTestOptions& o) {
  int need = o.pool3x3 ? o.min_spp_pooled : o.min_spp;
  if (n < need)
    return "spp " + std::to_string(n) + " < " + std::to_string(need) +
           (o.pool3x3 ? " (pooled)" : " (unpooled: per-pixel variance has only n-1 dof; pool or raise spp)");
  return {};
}

}  // namespace detail

// Options for renders whose samples are Bernoulli-like (the absorption
// estimator returns Le or the background; a light is hit or missed): the
// per-pixel variance pooled over 3×3 (pixel_stats explains; pooling only
// widens), with the given whole-image bias tolerance (relative).
inline ZTestOptions pooled(double bias_tolerance = ZTestOptions{}.bias_tolerance) {
  ZTestOptions o;
  o.pool3x3 = true;
  o.bias_tolerance = bias_tolerance;
  return o;
}

// The mean of pixel (x, y): sum / spp per channel.
inline glm::dvec3 pixel_mean(const RenderResult& r, int x, int y) {
  const size_t p = (size_t(y) * r.width + x) * 3;
  return glm::dvec3(r.sum[p], r.sum[p + 1], r.sum[p + 2]) / double(r.spp);
}

// Largest per-channel sample variance of pixel (x, y) relative to 1 + mean²:
// ~0 when every sample had the same value (what an exact per-sample closed
// form predicts): Σx²/n − mean² cancels to ~1e-16 with double sums (CPU),
// ~1e-7 with float sums (GPU).
inline double pixel_spread(const RenderResult& r, int x, int y) {
  const size_t p = (size_t(y) * r.width + x) * 3;
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double m = r.sum[p + c] / r.spp;
    worst = std::max(worst, std::abs(r.sum_sq[p + c] / r.spp - m * m) / (1.0 + m * m));
  }
  return worst;
}

// A w×h render of n samples per pixel whose sums are still 0 (test renders
// built by hand: fakes, crops).
inline RenderResult zero_render(int w, int h, int n) {
  RenderResult r;
  r.width = w;
  r.height = h;
  r.spp = n;
  r.sum.assign(size_t(w) * h * 3, 0.0);
  r.sum_sq.assign(size_t(w) * h * 3, 0.0);
  return r;
}

// The render's alpha (Σα, Σα²) as an image whose three channels all hold it,
// so that the z-tests below compare alpha (docs/compositing.md).
inline RenderResult alpha_image(const RenderResult& r) {
  RenderResult a = r;
  if (r.alpha_sum.size() * 3 != r.sum.size()) throw std::logic_error("alpha_image: the render has no alpha");
  for (size_t i = 0; i < r.alpha_sum.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      a.sum[i * 3 + c] = r.alpha_sum[i];
      a.sum_sq[i * 3 + c] = r.alpha_sum_sq[i];
    }
  return a;
}

// Render vs closed form. `exact(x, y)` is the expected pixel value (the average
// of the radiance over the pixel's area: the renderer jitters, box filter).
inline ZTestReport ztest_against_exact(const RenderResult& r, const std::function<glm::dvec3(int x, int y)>& exact,
                                       const ZTestOptions& o = {}) {
  ZTestReport fail;
  if (std::string p = detail::check_spp(r.spp, o); !p.empty()) {
    fail.problem = p;
    return fail;
  }
  PixelStats a = pixel_stats(r, o.pool3x3);
  std::vector<double> a_raw = o.pool3x3 ? pixel_stats(r, false).se : a.se;
  PixelStats b;
  b.width = r.width;
  b.height = r.height;
  b.n = 0;
  b.mean.assign(a.mean.size(), 0.0);
  b.se.assign(a.mean.size(), 0.0);
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      glm::dvec3 e = exact(x, y);
      for (int c = 0; c < 3; ++c) b.mean[(size_t(y) * r.width + x) * 3 + c] = e[c];
    }
  return detail::ztest_core(a, a_raw, b, b.se, o);
}

// Two renders of the same scene (e.g. Vulkan vs CPU). ΣB is the second image's.
inline ZTestReport ztest_images(const RenderResult& a, const RenderResult& b, const ZTestOptions& o = {}) {
  ZTestReport fail;
  if (a.width != b.width || a.height != b.height) {
    fail.problem = "image sizes differ";
    return fail;
  }
  std::string p = detail::check_spp(a.spp, o);
  if (p.empty()) p = detail::check_spp(b.spp, o);
  if (!p.empty()) {
    fail.problem = p;
    return fail;
  }
  PixelStats pa = pixel_stats(a, o.pool3x3), pb = pixel_stats(b, o.pool3x3);
  std::vector<double> a_raw = o.pool3x3 ? pixel_stats(a, false).se : pa.se;
  std::vector<double> b_raw = o.pool3x3 ? pixel_stats(b, false).se : pb.se;
  return detail::ztest_core(pa, a_raw, pb, b_raw, o);
}

// ---- chi-square goodness of fit (for samplers: HG phase, free flights, CDFs) ----

// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes 3rd ed. §6.2:
// series for x < a + 1, Lentz continued fraction otherwise).
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int i = 0; i < 10000; ++i) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

struct ChiSquareResult {
  double chi2 = 0.0;
  int dof = 0;
  double p_value = 0.0;
  std::string summary() const {
    char buf[128];
    std::snprintf(buf, sizeof buf, "chi2 %.2f, dof %d, p %.4g", chi2, dof, p_value);
    return buf;
  }
};

// Pearson chi-square of observed counts vs expected counts. Bins whose expected
// count is below min_expected are merged into one pooled bin (Mitsuba 3's
// chi2 harness does the same) so the chi-square approximation holds. An observed
// count in a bin with expected 0 gives p = 0 (the sampler produced the impossible).
inline ChiSquareResult chi_square(const std::vector<double>& observed, const std::vector<double>& expected,
                                  double min_expected = 5.0) {
  ChiSquareResult r;
  double pooled_obs = 0.0, pooled_exp = 0.0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] <= 0.0) {
      if (observed[i] > 0.0) {
        r.chi2 = std::numeric_limits<double>::infinity();
        r.p_value = 0.0;
        return r;
      }
      continue;
    }
    if (expected[i] < min_expected) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    double d = observed[i] - expected[i];
    r.chi2 += d * d / expected[i];
    ++bins;
  }
  if (pooled_exp > 0.0) {
    double d = pooled_obs - pooled_exp;
    r.chi2 += d * d / pooled_exp;
    ++bins;
  }
  r.dof = std::max(1, bins - 1);
  r.p_value = gamma_q(0.5 * r.dof, 0.5 * r.chi2);
  return r;
}

}  // namespace pyrolume::test
