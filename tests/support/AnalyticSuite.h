#pragma once
// Homogeneous media against closed forms (issue 2: analytic tests) on either
// backend. One body per case, instantiated for the CPU reference by
// tests/unit/cpu_analytic_test.cpp and for Vulkan by
// tests/vulkan/vulkan_analytic_test.cpp (BackendSuite.h explains); the cases
// only one backend has stay in those files. Absorption-estimator samples are
// Le or background (Bernoulli-like): silhouette pixels with few hits can show
// s² = 0 by chance, so the z-tests pool (Stats.h explains).
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "support/AnalyticScenes.h"
#include "support/BackendSuite.h"
#include "support/Stats.h"

namespace pyrolume::test {

class AnalyticFixture : public BackendFixture {
 protected:
  using BackendFixture::BackendFixture;

  // The render against single_collision_exact, informative to SE_bias 0.25 %.
  void expect_single_collision_closed_form(const Scene& s) {
    RenderResult r = render(s);
    ZTestReport rep = ztest_against_exact(r, single_collision_exact(s), pooled());
    EXPECT_TRUE(rep.ok) << rep.summary();
    EXPECT_LE(rep.se_bias, 0.0025) << rep.summary();
    std::printf("%s\n", rep.summary().c_str());
  }
};

using Analytic = BackendSuite<AnalyticFixture>;

TEST_P(Analytic, AbsorbingSphereMatchesClosedForm) { expect_single_collision_closed_form(absorbing_sphere_scene()); }

TEST_P(Analytic, AbsorbingBoxMatchesClosedForm) { expect_single_collision_closed_form(absorbing_box_scene()); }

// film.transparent on the absorbing sphere (chromatic σa, a background):
// escaping camera rays add nothing, so RGB = Le(1 − e^(−σa ℓ)) per channel,
// and alpha = 1 − avg_c e^(−σa_c ℓ) (docs/compositing.md "Alpha"). Both are
// pixel averages of the closed forms; alpha is z-tested as an image whose three
// channels all hold it. A closed form with the red channel's σa alone must fail.
TEST_P(Analytic, TransparentSphereRgbAndAlphaMatchClosedForms) {
  Scene s = absorbing_sphere_scene(40, 32, 512);
  s.film.transparent = true;
  RenderResult r = render(s);
  Scene no_background = s;
  no_background.background = glm::dvec3(0.0);
  ZTestReport rgb = ztest_against_exact(r, single_collision_exact(no_background), pooled());
  EXPECT_TRUE(rgb.ok) << rgb.summary();
  std::printf("rgb: %s\n", rgb.summary().c_str());

  ASSERT_EQ(r.alpha_sum.size(), size_t(r.width) * r.height);
  const RenderResult alpha = alpha_image(r);
  const Medium& m = s.media[0];
  auto alpha_exact = [&](glm::dvec3 sigma) {
    return pixel_average_image(s.film.width, s.film.height, [&, sigma](double fx, double fy, int* sig) {
      const Chord ch = chord(m.bounds, s.camera.position, film_ray(s.camera, s.film.width, s.film.height, fx, fy));
      if (sig) *sig = ch.signature;
      const double T = (std::exp(-sigma.x * ch.length) + std::exp(-sigma.y * ch.length) +
                        std::exp(-sigma.z * ch.length)) / 3.0;
      return glm::dvec3(1.0 - T);
    });
  };
  ZTestReport rep = ztest_against_exact(alpha, alpha_exact(m.sigma_a), pooled());
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("alpha: %s\n", rep.summary().c_str());
  ZTestReport wrong = ztest_against_exact(alpha, alpha_exact(glm::dvec3(m.sigma_a.x)), pooled());
  EXPECT_FALSE(wrong.ok) << wrong.summary();
}

// Thin, hot media with the scene's default estimator ("auto": the line
// estimator, which each backend reports).
TEST_P(Analytic, ThinEmissiveSphereMatchesClosedFormByDefault) {
  const Scene s = thin_sphere_scene();
  EXPECT_EQ(render(thin_sphere_scene(8, 8, 1)).emission_estimator, "line");
  expect_single_collision_closed_form(s);
}

TEST_P(Analytic, ThinEmissiveSlabMatchesClosedFormByDefault) {
  const Scene s = thin_slab_scene();
  EXPECT_EQ(render(thin_slab_scene(8, 8, 1)).emission_estimator, "line");
  expect_single_collision_closed_form(s);
}

// The hard case: optical depth 1e-6 across the slab, emission 1e6 (L ≈ 1).
// One camera ray in a million would meet a collision.
TEST_P(Analytic, OpticalDepthOneInAMillionWithEmissionOfAMillion) {
  const Scene s = thin_slab_scene(40, 32, 64, 1e-6);
  RenderResult r = render(s);
  EXPECT_EQ(r.emission_estimator, "line");
  EXPECT_EQ(r.nonfinite_samples, 0u);
  ZTestReport rep = ztest_against_exact(r, single_collision_exact(s), pooled());
  EXPECT_TRUE(rep.ok) << rep.summary();
  EXPECT_LE(rep.se_bias, 0.0025) << rep.summary();
  std::printf("%s\n", rep.summary().c_str());
}

TEST_P(Analytic, MaxDepthZeroTreatsScatteringAsExtinction) {
  Scene s = depth0_sphere_scene();
  RenderResult r = render(s);
  ZTestReport rep = ztest_against_exact(r, single_collision_exact(s), pooled());
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("%s\n", rep.summary().c_str());
  // The same scene with scattering allowed is brighter (in-scattered emission):
  // max_depth really truncates.
  s.integrator.max_depth = 8;
  ZTestReport deeper = ztest_against_exact(render(s), single_collision_exact(s), pooled());
  EXPECT_FALSE(deeper.bias_ok) << deeper.summary();
  EXPECT_GT(deeper.bias, 0.0);
}

TEST_P(Analytic, EquilibriumInsideLargeSphere) {
  Scene s = equilibrium_sphere_scene();
  RenderResult r = render(s);
  glm::dvec3 Le = equilibrium_radiance(s);
  ZTestReport rep = ztest_against_exact(r, [&](int, int) { return Le; });
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("%s\n", rep.summary().c_str());
  if (cpu()) {
    // The CPU tracks each channel's walk: expected collisions per channel walk
    // until absorption: σt/σa (geometric).
    double expect = 0.0;
    for (int c = 0; c < 3; ++c) {
      const Medium& m = s.media[0];
      expect += (m.sigma_a[c] + m.sigma_s[c]) / m.sigma_a[c] / 3.0;
    }
    double per_sample = r.events / (double(r.width) * r.height * r.spp);
    EXPECT_NEAR(per_sample, expect, 0.02 * expect);
    EXPECT_EQ(r.density_lookups, 0.0);
  }
}

TEST_P(Analytic, WhiteFurnaceConservesEnergy) {
  Scene s = white_furnace_scene();
  ZTestReport rep = ztest_against_exact(render(s), [&](int, int) { return s.background; });
  EXPECT_TRUE(rep.ok) << rep.summary();
}

}  // namespace pyrolume::test
