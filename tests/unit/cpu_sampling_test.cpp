// Samplers and geometry of the CPU reference: chi-square tests against the
// analytic distributions (docs/testing.md: samplers get chi-square tests).
#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "render/cpu/Intersect.h"
#include "render/cpu/Rng.h"
#include "render/cpu/Sampling.h"
#include "support/Stats.h"

namespace pyrolume::cpu {
namespace {

// Analytic CDF of cos θ under HG (propagation convention, g > 0 forward):
//   P(cos θ <= μ) = (1 − g²)/(2g) · [(1 + g² − 2gμ)^{−1/2} − (1 + g)^{−1}]
double hg_cdf(double mu, double g) {
  if (std::abs(g) < 1e-12) return 0.5 * (mu + 1.0);
  return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * mu) - 1.0 / (1.0 + g));
}

const double kGs[] = {-0.95, -0.7, -0.3, -1e-4, 0.0, 1e-4, 5e-4, 5e-3, 0.3, 0.7, 0.95};

TEST(CpuSampling, HgPdfIsNormalisedAndMatchesCdf) {
  for (double g : kGs) {
    // ∫ p dω = 2π ∫_{-1}^{1} p(μ) dμ, Simpson on a fine grid.
    const int n = 200000;
    double h = 2.0 / n, acc = 0.0;
    for (int i = 0; i <= n; ++i) {
      double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      acc += w * hg_pdf(-1.0 + i * h, g);
    }
    double integral = 2.0 * std::numbers::pi * acc * h / 3.0;
    EXPECT_NEAR(integral, 1.0, 1e-6) << "g " << g;
    EXPECT_NEAR(hg_cdf(1.0, g), 1.0, 1e-9);
    EXPECT_NEAR(hg_cdf(-1.0, g), 0.0, 1e-12);
  }
  // g > 0 scatters forward: more density at cos θ = 1 than at −1.
  EXPECT_GT(hg_pdf(1.0, 0.5), hg_pdf(-1.0, 0.5));
  EXPECT_LT(hg_pdf(1.0, -0.5), hg_pdf(-1.0, -0.5));
  EXPECT_DOUBLE_EQ(hg_pdf(0.3, 0.0), 1.0 / (4.0 * std::numbers::pi));
}

TEST(CpuSampling, SampleHgChiSquareAndMeanCosine) {
  const glm::dvec3 dirs[] = {{0, 0, 1}, {0, 0, -1}, glm::normalize(glm::dvec3(0.3, -0.8, 0.2)), {1, 0, 0}};
  Pcg32 rng(42, 7);
  for (double g : kGs)
    for (const glm::dvec3& dir : dirs) {
      const int N = 40000, mu_bins = 20, phi_bins = 8;
      std::vector<double> obs(mu_bins * phi_bins, 0.0), expct(mu_bins * phi_bins, 0.0);
      // An independent frame around dir to measure φ.
      glm::dvec3 a = std::abs(dir.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
      glm::dvec3 t = glm::normalize(glm::cross(dir, a)), b = glm::cross(dir, t);
      double mean_cos = 0.0;
      for (int i = 0; i < N; ++i) {
        PhaseSample ps = sample_hg(dir, g, {rng.uniform(), rng.uniform()});
        double mu = glm::dot(ps.direction, dir);
        ASSERT_NEAR(glm::length(ps.direction), 1.0, 1e-12);
        ASSERT_NEAR(ps.pdf, hg_pdf(mu, g), 1e-9 * ps.pdf + 1e-12);
        mean_cos += mu / N;
        double phi = std::atan2(glm::dot(ps.direction, b), glm::dot(ps.direction, t)) + std::numbers::pi;
        // Bins equal in probability would hide shape errors at the peak; use
        // equal-width bins in μ and pool rare ones (chi_square does).
        int im = std::min(mu_bins - 1, int((mu + 1.0) * 0.5 * mu_bins));
        int ip = std::min(phi_bins - 1, int(phi / (2.0 * std::numbers::pi) * phi_bins));
        obs[im * phi_bins + ip] += 1.0;
      }
      for (int im = 0; im < mu_bins; ++im) {
        double p = hg_cdf(-1.0 + 2.0 * (im + 1) / mu_bins, g) - hg_cdf(-1.0 + 2.0 * im / mu_bins, g);
        for (int ip = 0; ip < phi_bins; ++ip) expct[im * phi_bins + ip] = N * p / phi_bins;
      }
      test::ChiSquareResult cs = test::chi_square(obs, expct);
      EXPECT_GT(cs.p_value, 1e-4) << "g " << g << " dir " << dir.x << "," << dir.y << "," << dir.z << ": "
                                  << cs.summary();
      // E[cos θ] = g for HG; the sample mean's SD is <= 1/sqrt(N).
      EXPECT_NEAR(mean_cos, g, 5.0 / std::sqrt(double(N))) << "g " << g;
    }
}

// |g| tiny: still exactly HG (not pbrt-v4's isotropic stand-in). The mean cosine
// of HG is g; integrate the inverse CDF over u (midpoint rule, smooth integrand).
TEST(CpuSampling, SampleHgSmallGIsExact) {
  for (double g : {1e-6, -3e-5, 4e-4}) {
    const int n = 200000;
    double mean = 0.0;
    for (int i = 0; i < n; ++i) mean += sample_hg_cos_theta(g, (i + 0.5) / n) / n;
    EXPECT_NEAR(mean, g, 1e-9 + 1e-3 * std::abs(g)) << "g " << g;
  }
  // Continuous across the branch switch at |g| = kHgSmallG.
  for (double u : {0.01, 0.3, 0.77, 0.999}) {
    EXPECT_NEAR(sample_hg_cos_theta(kHgSmallG * (1 - 1e-9), u), sample_hg_cos_theta(kHgSmallG, u), 1e-9);
    EXPECT_NEAR(sample_hg_cos_theta(-kHgSmallG * (1 - 1e-9), u), sample_hg_cos_theta(-kHgSmallG, u), 1e-9);
  }
}

TEST(CpuSampling, SampleHgExtremeInputsStayFinite) {
  for (double g : {-0.999999, -1e-300, 0.0, 1e-300, 1e-3, 0.999999})
    for (double u : {0.0, 1e-17, 0.5, 1.0 - 1e-16}) {
      PhaseSample ps = sample_hg({0, 0, -1}, g, {u, u});
      EXPECT_TRUE(std::isfinite(ps.direction.x) && std::isfinite(ps.direction.y) && std::isfinite(ps.direction.z));
      EXPECT_TRUE(std::isfinite(ps.pdf)) << g << " " << u;
      EXPECT_NEAR(glm::length(ps.direction), 1.0, 1e-12);
    }
  // u = 0 is straight back, u -> 1 straight ahead (forward for g > 0).
  EXPECT_NEAR(sample_hg_cos_theta(0.5, 0.0), -1.0, 1e-12);
  EXPECT_NEAR(sample_hg_cos_theta(0.5, 1.0 - 1e-16), 1.0, 1e-9);
}

TEST(CpuSampling, FreeFlightIsExponential) {
  const double sigma_t = 2.5;
  const int N = 100000, bins = 40;
  const double tmax = 3.0;  // last bin collects t >= tmax
  std::vector<double> obs(bins + 1, 0.0), expct(bins + 1, 0.0);
  Pcg32 rng(3, 9);
  double mean = 0.0;
  for (int i = 0; i < N; ++i) {
    double t = sample_free_flight(sigma_t, rng.uniform());
    ASSERT_GE(t, 0.0);
    mean += t / N;
    obs[t >= tmax ? bins : int(t / tmax * bins)] += 1.0;
  }
  for (int i = 0; i < bins; ++i)
    expct[i] = N * (std::exp(-sigma_t * tmax * i / bins) - std::exp(-sigma_t * tmax * (i + 1) / bins));
  expct[bins] = N * std::exp(-sigma_t * tmax);
  test::ChiSquareResult cs = test::chi_square(obs, expct);
  EXPECT_GT(cs.p_value, 1e-4) << cs.summary();
  EXPECT_NEAR(mean, 1.0 / sigma_t, 5.0 / sigma_t / std::sqrt(double(N)));
  EXPECT_EQ(sample_free_flight(0.0, 0.5), std::numeric_limits<double>::infinity());
  EXPECT_EQ(sample_free_flight(1.0, 0.0), 0.0);
  EXPECT_TRUE(std::isfinite(sample_free_flight(1e-300, 1.0 - 1e-16)));
}

TEST(CpuSampling, RngUniformAndKeyed) {
  Pcg32 a = Pcg32::for_sample(1, 0, 5, 3), b = Pcg32::for_sample(1, 0, 5, 3);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(a.next_u32(), b.next_u32());
  // Neighbouring keys give different streams.
  std::set<uint32_t> firsts;
  for (uint32_t seed = 0; seed < 4; ++seed)
    for (uint32_t frame = 0; frame < 4; ++frame)
      for (uint64_t pix = 0; pix < 8; ++pix)
        for (uint64_t s = 0; s < 8; ++s) firsts.insert(Pcg32::for_sample(seed, frame, pix, s).next_u32());
  EXPECT_GE(firsts.size(), 1020u);  // 1024 keys; a 32-bit collision or two is fine
  // Uniformity, pooled over many short per-sample streams (how the renderer uses it).
  const int bins = 64;
  std::vector<double> obs(bins, 0.0), expct(bins, 0.0);
  int n = 0;
  for (uint64_t pix = 0; pix < 4096; ++pix)
    for (uint64_t s = 0; s < 8; ++s) {
      Pcg32 r = Pcg32::for_sample(1, 0, pix, s);
      for (int k = 0; k < 4; ++k) {
        double u = r.uniform();
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        obs[int(u * bins)] += 1.0;
        ++n;
      }
    }
  for (double& e : expct) e = double(n) / bins;
  EXPECT_GT(test::chi_square(obs, expct).p_value, 1e-4);
}

TEST(CpuIntersect, SphereTangentInsideAndMiss) {
  // Tangent: a zero-length interval at t = 5, no NaN.
  RayInterval r = intersect_sphere({-5, 1, 0}, {1, 0, 0}, {0, 0, 0}, 1.0);
  if (r.hit) {
    EXPECT_NEAR(r.t0, 5.0, 1e-7);
    EXPECT_NEAR(r.t1, 5.0, 1e-7);
  }
  EXPECT_FALSE(intersect_sphere({-5, 1.0 + 1e-12, 0}, {1, 0, 0}, {0, 0, 0}, 1.0).hit);
  // Through the centre from inside.
  r = intersect_sphere({0.5, 0, 0}, {1, 0, 0}, {0, 0, 0}, 1.0);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t0, -1.5, 1e-12);
  EXPECT_NEAR(r.t1, 0.5, 1e-12);
  // Distant sphere: precision of the perpendicular-distance discriminant.
  r = intersect_sphere({0, 0, -1e6}, {0, 0, 1}, {0, 0, 0}, 1e-3);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t1 - r.t0, 2e-3, 1e-9);
}

TEST(CpuIntersect, BoxParallelAndOnFace) {
  glm::dvec3 lo(-1, -1, -1), hi(1, 1, 1);
  // Lying on the face plane y = 1, parallel to it: inside (closed box), no NaN.
  RayInterval r = intersect_box({-3, 1, 0}, {1, 0, 0}, lo, hi);
  ASSERT_TRUE(r.hit);
  EXPECT_DOUBLE_EQ(r.t0, 2.0);
  EXPECT_DOUBLE_EQ(r.t1, 4.0);
  // Parallel, outside.
  EXPECT_FALSE(intersect_box({-3, 1.5, 0}, {1, 0, 0}, lo, hi).hit);
  // Origin on a face, pointing out: interval ends at 0.
  r = intersect_box({0, 0, -1}, {0, 0, -1}, lo, hi);
  ASSERT_TRUE(r.hit);
  EXPECT_DOUBLE_EQ(r.t1, 0.0);
  // Diagonal through an edge.
  r = intersect_box({-2, -2, 0}, glm::normalize(glm::dvec3(1, 1, 0)), lo, hi);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t1 - r.t0, 2.0 * std::sqrt(2.0), 1e-12);
}

}  // namespace
}  // namespace pyrolume::cpu
