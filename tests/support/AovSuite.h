#pragma once
// film.aovs (docs/compositing.md "AOVs") on both backends: the light layers
// add up to the beauty, each layer gets what it should, and the first-hit
// features match the geometry they come from.
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "render/RenderImage.h"
#include "support/AnalyticScenes.h"
#include "support/BackendSuite.h"
#include "support/GuideChecks.h"
#include "support/LightScenes.h"
#include "support/SurfaceScenes.h"

namespace pyrolume::test {

// An emissive, scattering, chromatic sphere over a plane before a constant
// background: every light layer has light (the sphere's own emission, light
// it scatters, the lit plane, the background around them).
inline Scene aov_layers_scene(int spp, uint32_t seed) {
  Scene s = analytic_base_scene(24, 16, spp);
  s.film.seed = seed;
  s.film.aovs = true;
  s.camera.position = {1.0, -6.0, 2.5};
  s.camera.look_at = {0.0, 0.0, 0.6};
  s.camera.up = {0, 0, 1};
  s.integrator.max_depth = 4;
  s.background = glm::dvec3(0.3, 0.4, 0.6);
  s.shapes.push_back(plane_shape({0, 0, 0}, {0, 0, 1}, {6, 6}, {0.8, 0.7, 0.6}));
  s.media.push_back(
      homogeneous_sphere("fire", {0.2, 0.3, 1.2}, 0.9, {0.8, 0.5, 0.3}, {1.0, 1.5, 2.0}, 0.3, glm::dvec3(3.0, 1.5, 0.5)));
  return s;
}

// Straight down onto a plane, with an optically thick grey sphere medium
// (σt = 40, albedo σs/σt = 0.75) between: pixels see one or the other.
inline Scene aov_features_scene(int spp) {
  Scene s = analytic_base_scene(24, 24, spp);
  s.film.aovs = true;
  s.camera.position = {0.0, 0.0, 5.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.up = {0, 1, 0};
  s.background = glm::dvec3(0.5);
  s.shapes.push_back(plane_shape({0, 0, 0}, {0, 0, 1}, {0, 0}, {0.8, 0.6, 0.4}));
  s.media.push_back(homogeneous_sphere("grey", {0.5, 0.3, 1.0}, 0.6, glm::dvec3(10.0), glm::dvec3(30.0), 0.0,
                                       glm::dvec3(1.0)));
  return s;
}

class Aovs : public BackendSuite<BackendFixture> {};

TEST_P(Aovs, LightLayersSumToTheBeautyAndEachHasItsLight) {
  const Scene s = aov_layers_scene(per_backend(16, 64), 3);
  const RenderResult r = render(s);
  ASSERT_EQ(r.aov_sum.size(), size_t(r.width) * r.height * kAovValues);
  // Rounding only: the layers are one split of each sample's L, summed in
  // the accumulation's precision (double on the CPU, float on the GPU, whose
  // layer sums have no Kahan terms): at most about (spp + passes) roundings
  // of the magnitudes involved.
  const double eps = per_backend(std::numeric_limits<double>::epsilon(), double(std::numeric_limits<float>::epsilon()));
  const double bound = 4.0 * (r.spp + 8) * eps;
  double total[4] = {0, 0, 0, 0};
  int worst_x = -1;
  double worst = 0.0;
  for (size_t i = 0; i < size_t(r.width) * r.height; ++i)
    for (int c = 0; c < 3; ++c) {
      const double* a = r.aov_sum.data() + i * kAovValues;
      const double layers[4] = {a[kAovEmission + c], a[kAovScatter + c], a[kAovSurface + c], a[kAovBackground + c]};
      double sum = 0.0, magnitude = std::abs(r.sum[i * 3 + c]);
      for (int k = 0; k < 4; ++k) {
        sum += layers[k];
        magnitude += std::abs(layers[k]);
        total[k] += layers[k];
        EXPECT_GE(layers[k], -bound * magnitude - 1e-30) << "pixel " << i << " layer " << k << " is negative";
      }
      const double excess = std::abs(sum - r.sum[i * 3 + c]) / std::max(magnitude, 1e-30);
      if (excess > worst) {
        worst = excess;
        worst_x = int(i);
      }
    }
  std::printf("layers vs beauty: worst relative difference %.3g (bound %.3g) at pixel %d\n", worst, bound, worst_x);
  EXPECT_LE(worst, bound);
  const char* names[4] = {"emission", "scatter", "surface", "background"};
  for (int k = 0; k < 4; ++k) EXPECT_GT(total[k], 0.0) << names[k] << " layer is empty";
  // The layers as an image: the same split of the beauty, per pixel.
  const Image img = image_from_render(r, false);
  ASSERT_TRUE(img.has_aovs());
  for (size_t i = 0; i < img.rgb.size(); ++i)
    EXPECT_NEAR(img.aovs.emission[i] + img.aovs.scatter[i] + img.aovs.surface[i] + img.aovs.background[i], img.rgb[i],
                1e-5 * std::abs(img.rgb[i]) + 1e-7);
}

// The features of the first event: a surface's albedo, normal (facing the
// camera) and distance; in a homogeneous grey medium, σs/σt and normal 0.
TEST_P(Aovs, FeaturesAreThoseOfTheFirstHit) {
  const Scene s = aov_features_scene(per_backend(8, 32));
  const RenderResult r = render(s);
  const Image img = image_from_render(r, false);
  ASSERT_TRUE(img.has_aovs());
  const Camera& cam = s.camera;
  const Medium& m = s.media[0];
  // What the ray through film point (fx, fy) meets first: its distance to
  // the sphere, or nullopt.
  auto sphere_t = [&](double fx, double fy) -> std::optional<double> {
    const glm::dvec3 d = film_ray(cam, r.width, r.height, fx, fy), oc = cam.position - m.bounds.center;
    const double b = glm::dot(oc, d), disc = b * b - (glm::dot(oc, oc) - m.bounds.radius * m.bounds.radius);
    if (disc <= 0.0) return std::nullopt;
    return -b - std::sqrt(disc);
  };
  int plane_pixels = 0, medium_pixels = 0;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      int inside = 0;
      for (double fy : {0.0, 0.5, 1.0})
        for (double fx : {0.0, 0.5, 1.0}) inside += sphere_t(x + fx, y + fy) ? 1 : 0;
      const size_t p = size_t(y) * r.width + x;
      if (inside == 0) {  // the plane: exact albedo and normal, distance over the pixel
        ++plane_pixels;
        const glm::dvec3 d = film_ray(cam, r.width, r.height, x + 0.5, y + 0.5);
        const double t = -cam.position.z / d.z;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.aovs.albedo[p * 3 + c], s.shapes[0].albedo[c], 1e-5);
        EXPECT_NEAR(img.aovs.normal[p * 3 + 0], 0.0, 1e-5);
        EXPECT_NEAR(img.aovs.normal[p * 3 + 1], 0.0, 1e-5);
        EXPECT_NEAR(img.aovs.normal[p * 3 + 2], 1.0, 1e-5);
        EXPECT_NEAR(img.aovs.depth[p], t, 0.01 * t) << "pixel " << x << "," << y;
      } else if (inside == 9) {  // the medium: almost every camera ray collides within a few 1/σt
        ++medium_pixels;
        const double t = *sphere_t(x + 0.5, y + 0.5);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.aovs.albedo[p * 3 + c], 0.75, 1e-4);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.aovs.normal[p * 3 + c], 0.0, 1e-6);
        EXPECT_GT(img.aovs.depth[p], t - 0.05);
        EXPECT_LT(img.aovs.depth[p], t + 0.15);  // the mean free path is 1/40
      }
    }
  EXPECT_GT(plane_pixels, 100);
  EXPECT_GT(medium_pixels, 10);
}

// A sphere light seen directly: albedo 0, its outward normal (toward the
// camera that sees it), the distance to its surface.
TEST_P(Aovs, SphereLightFeaturesAreItsOutwardNormalAndDistance) {
  Scene s = analytic_base_scene(16, 16, 4);
  s.film.aovs = true;
  s.camera.position = {0.0, 0.0, 5.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.fov_deg = 10.0;  // the light fills the view
  s.lights.push_back(sphere_light({0.0, 0.0, 0.0}, 1.0, glm::dvec3(2.0)));
  const RenderResult r = render(s);
  const Image img = image_from_render(r, false);
  ASSERT_TRUE(img.has_aovs());
  const size_t p = size_t(8) * r.width + 8;  // next to the view's centre
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.aovs.albedo[p * 3 + c], 0.0, 1e-6);
  EXPECT_GT(img.aovs.normal[p * 3 + 2], 0.99) << "the normal faces the camera (+Z)";
  EXPECT_NEAR(img.aovs.depth[p], 4.0, 0.01);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.aovs.background[p * 3 + c], img.rgb[p * 3 + c], 1e-5);
}

// The denoiser's guide is the expected `emission` + `background` layers (the
// ray march is exact for a homogeneous medium: one step per chord) and its
// alpha the expected alpha 1 − avg_c T_c: over the pixels, the mean of the
// pixelwise differences layers − guide (noise only, as the guide has none)
// is within 4 SE of 0, per channel. The sphere is chromatic and scatters,
// half of it stands in front of a plane, so the march must stop at the
// surface, and the rest before the background, which it must attenuate. With
// film.transparent the background is in neither.
TEST_P(Aovs, GuideIsTheExpectedEmissionAndBackgroundLayersAndAlpha) {
  for (const bool transparent : {false, true}) {
    SCOPED_TRACE(transparent ? "film.transparent" : "background");
    Scene s = aov_layers_scene(per_backend(64, 256), 11);
    s.film.transparent = transparent;
    const RenderResult r = render(s);
    const Image img = image_from_render(r, false);
    ASSERT_TRUE(img.aovs.has_guide());
    ASSERT_TRUE(img.has_alpha());
    const size_t n = img.pixel_count();
    double guide_total = 0.0;
    for (int c = 0; c < 4; ++c) {  // R, G, B of emission + background; 3: alpha
      double sum = 0.0, sq = 0.0;
      for (size_t i = 0; i < n; ++i) {
        const size_t k = i * 3 + c;
        const double d = c < 3 ? double(img.aovs.emission[k]) + img.aovs.background[k] - img.aovs.guide[k]
                               : double(img.alpha[i]) - img.aovs.guide_alpha[i];
        sum += d;
        sq += d * d;
        if (c < 3) guide_total += img.aovs.guide[k];
      }
      const double mean = sum / double(n), se = std::sqrt(std::max(sq / double(n) - mean * mean, 0.0) / double(n));
      std::printf("%s channel %d: mean(layers - guide) %.4g, SE %.3g\n", transparent ? "transparent" : "opaque", c,
                  mean, se);
      EXPECT_LE(std::abs(mean), 4.0 * se + 1e-6) << "channel " << c;
    }
    EXPECT_GT(guide_total, 0.0);
    // Deterministic up to the film positions: where the camera sees only the
    // plane (the bottom row's corners) the guide is exactly 0, and where it
    // sees only the background (the top row's corner), that (to rounding).
    EXPECT_EQ(img.aovs.guide[(n - 1) * 3], 0.0f);
    EXPECT_NEAR(img.aovs.guide[0], transparent ? 0.0 : s.background.x, 1e-6);
  }
}

// A sphere light that the camera sees is in the guide too (the `background`
// layer has it), and makes the guide's alpha 1 there.
TEST_P(Aovs, GuideHasTheSphereLightsTheCameraSees) {
  Scene s = aov_layers_scene(4, 2);
  s.media.clear();
  s.shapes.clear();
  s.camera.position = {0.0, 0.0, 4.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.up = {0, 1, 0};
  s.camera.fov_deg = 10.0;  // the light fills the view
  s.lights.push_back(sphere_light({0.0, 0.0, 0.0}, 1.0, glm::dvec3(2.0, 3.0, 4.0)));
  const RenderResult r = render(s);
  const Image img = image_from_render(r, false);
  ASSERT_TRUE(img.aovs.has_guide());
  const size_t p = size_t(8) * r.width + 8;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.aovs.guide[p * 3 + c], 2.0 + c, 1e-5);
  EXPECT_NEAR(img.aovs.guide_alpha[p], 1.0, 1e-6);
}

// The guide is a fixed quadrature of each pixel (marches through its centre
// and corners), computed once per render, so its cost does not
// grow with the sample count: a 1-spp render and a 9-spp one (three passes
// on the CPU, whose later passes must carry it through) hold the same guide,
// value for value. A guide averaged over per-sample film points would differ.
TEST_P(Aovs, TheGuideIsMarchedOnceWhateverTheSampleCount) {
  const Image one = image_from_render(render(aov_layers_scene(1, 7)), false);
  const Image nine = image_from_render(render(aov_layers_scene(9, 8)), false);
  test::expect_same_guide(one, nine);
}

// Without film.aovs nothing is accumulated.
TEST_P(Aovs, NoneWhenNotAsked) {
  Scene s = aov_layers_scene(2, 5);
  s.film.aovs = false;
  const RenderResult r = render(s);
  EXPECT_TRUE(r.aov_sum.empty());
  EXPECT_EQ(r.guide_seconds, 0.0);  // no guide was marched
  EXPECT_FALSE(image_from_render(r, false).has_aovs());
}

}  // namespace pyrolume::test
