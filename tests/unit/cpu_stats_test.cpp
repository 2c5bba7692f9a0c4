// The statistical test support (tests/support/Stats.h) must itself be right:
// the standard error formula, acceptance of correct data, rejection of biased
// data, SE = 0 handling, pooling, and the chi-square p-value.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "support/Stats.h"

namespace pyrolume::test {
namespace {

// A fake render: per pixel-channel, n samples drawn from draw(x, y, c).
template <class F>
RenderResult fake_render(int w, int h, int n, F draw) {
  RenderResult r = zero_render(w, h, n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < n; ++i) {
          double v = draw(x, y, c);
          r.sum[(size_t(y) * w + x) * 3 + c] += v;
          r.sum_sq[(size_t(y) * w + x) * 3 + c] += v * v;
        }
  return r;
}

TEST(CpuStats, StandardErrorFormula) {
  // Samples 1, 2, 3, 4: mean 2.5, s² = 5/3 (n − 1 in the denominator), SE² = s²/n.
  EXPECT_NEAR(sample_variance(10.0, 30.0, 4), 5.0 / 3.0, 1e-14);
  int k = 0;
  RenderResult r = fake_render(1, 1, 4, [&](int, int, int) { return double(k++ % 4 + 1); });
  PixelStats ps = pixel_stats(r);
  EXPECT_NEAR(ps.mean[0], 2.5, 1e-15);
  EXPECT_NEAR(ps.se[0], std::sqrt(5.0 / 3.0 / 4.0), 1e-14);
  // Identical samples: cancellation must not invent a tiny SE.
  RenderResult c = fake_render(2, 2, 1000, [](int, int, int) { return 0.1; });
  for (double se : pixel_stats(c).se) EXPECT_EQ(se, 0.0);
}

TEST(CpuStats, AcceptsCorrectRejectsBiased) {
  std::mt19937_64 gen(1);
  std::normal_distribution<double> noise(0.0, 1.0);
  auto truth = [](int x, int y) { return glm::dvec3(1.0 + 0.01 * x, 2.0 + 0.02 * y, 0.5); };
  RenderResult r = fake_render(48, 48, 100, [&](int x, int y, int c) { return truth(x, y)[c] + 0.5 * noise(gen); });
  ZTestReport ok = ztest_against_exact(r, truth);
  EXPECT_TRUE(ok.ok) << ok.summary();
  // SE per pixel-channel 0.5/sqrt(100); ΣB = 48² · (1.235 + 2.47 + 0.5) (column/row means).
  const double n_ch = 48.0 * 48 * 3;
  EXPECT_NEAR(ok.se_bias, 0.05 * std::sqrt(n_ch) / (48.0 * 48 * (1.235 + 2.47 + 0.5)), 0.05 * ok.se_bias);
  // A 1 % brighter reference is 1 % bias: caught by the bias test.
  ZTestReport bright = ztest_against_exact(r, [&](int x, int y) { return 1.01 * truth(x, y); });
  EXPECT_FALSE(bright.ok);
  EXPECT_FALSE(bright.bias_ok) << bright.summary();
  // A 4-pixel-wide stripe off by 20σ: caught by the per-pixel fraction.
  ZTestReport stripe = ztest_against_exact(r, [&](int x, int y) { return truth(x, y) + (x < 4 ? 1.0 : 0.0); });
  EXPECT_FALSE(stripe.fraction_ok) << stripe.summary();
  // Two independent correct renders agree.
  RenderResult r2 = fake_render(48, 48, 100, [&](int x, int y, int c) { return truth(x, y)[c] + 0.5 * noise(gen); });
  ZTestReport pair = ztest_images(r, r2);
  EXPECT_TRUE(pair.ok) << pair.summary();
  EXPECT_NEAR(pair.se_bias, std::sqrt(2.0) * ok.se_bias, 0.1 * pair.se_bias);
}

TEST(CpuStats, BiasFormula) {
  // A: pixel means (2, 4), SE² = s²/n; B exact (1, 3): bias = (6 − 4)/4.
  RenderResult a = fake_render(2, 1, 64, [](int x, int, int) { return 2.0 + 2.0 * x; });
  ZTestOptions o;
  o.require_informative = false;
  ZTestReport rep = ztest_against_exact(a, [](int x, int) { return glm::dvec3(1.0 + 2.0 * x); }, o);
  EXPECT_DOUBLE_EQ(rep.bias, 0.5);
  EXPECT_EQ(rep.se_bias, 0.0);
  EXPECT_FALSE(rep.bias_ok);
  EXPECT_EQ(rep.zero_se_mismatches, 6u);
}

TEST(CpuStats, ZeroSeNeedsExactAgreement) {
  RenderResult r = fake_render(8, 8, 64, [](int, int, int) { return 0.25; });
  EXPECT_TRUE(ztest_against_exact(r, [](int, int) { return glm::dvec3(0.25 * (1 + 1e-9)); }).ok);
  ZTestReport off = ztest_against_exact(r, [](int, int) { return glm::dvec3(0.25 * (1 + 1e-4)); });
  EXPECT_FALSE(off.ok);
  EXPECT_EQ(off.zero_se_mismatches, 8u * 8 * 3);
}

TEST(CpuStats, FewSamplesNeedPooling) {
  std::mt19937_64 gen(2);
  std::normal_distribution<double> noise(0.0, 1.0);
  RenderResult r = fake_render(32, 32, 16, [&](int, int, int) { return 1.0 + noise(gen); });
  ZTestReport unpooled = ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); });
  EXPECT_FALSE(unpooled.ok);
  EXPECT_FALSE(unpooled.problem.empty());
  ZTestOptions o;
  o.pool3x3 = true;
  o.require_informative = false;
  ZTestReport pooled = ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); }, o);
  EXPECT_TRUE(pooled.problem.empty());
  EXPECT_TRUE(pooled.fraction_ok) << pooled.summary();
  // Pooling never shrinks a pixel's SE below its own.
  PixelStats own = pixel_stats(r, false), pool = pixel_stats(r, true);
  for (size_t i = 0; i < own.se.size(); ++i) EXPECT_GE(pool.se[i], own.se[i]);
}

TEST(CpuStats, ChiSquarePValue) {
  // Q(1, x) = e^{−x}; χ² with 2 dof has p = e^{−χ²/2}.
  EXPECT_NEAR(gamma_q(1.0, 2.0), std::exp(-2.0), 1e-12);
  EXPECT_NEAR(gamma_q(1.0, 0.3), std::exp(-0.3), 1e-12);
  // Q(1/2, x) = erfc(sqrt(x)).
  EXPECT_NEAR(gamma_q(0.5, 4.0), std::erfc(2.0), 1e-12);
  // Integer a: Q(n, x) = e^{−x} Σ_{k<n} x^k/k!  (χ² with 20 dof at 60).
  double series = 0.0, term = 1.0;
  for (int k = 0; k < 10; ++k, term *= 30.0 / k) series += term;
  EXPECT_NEAR(gamma_q(10.0, 30.0), std::exp(-30.0) * series, 1e-15);
  ChiSquareResult cs = chi_square({10, 10, 10}, {10, 10, 10});
  EXPECT_EQ(cs.dof, 2);
  EXPECT_NEAR(cs.p_value, 1.0, 1e-12);
  EXPECT_EQ(chi_square({1, 0}, {0, 1}).p_value, 0.0);  // impossible event observed
}

}  // namespace
}  // namespace pyrolume::test
