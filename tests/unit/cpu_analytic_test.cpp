// CPU reference vs closed forms (issue 2: analytic tests): the cases both
// backends share run from tests/support/AnalyticSuite.h (Analytic.*/"cpu");
// here, the CPU-only ones, plus determinism, progressive control and
// robustness of the reference.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "color/Blackbody.h"
#include "render/cpu/CpuRenderer.h"
#include "support/AnalyticSuite.h"
#include "support/Stats.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Analytic, "cpu");
}  // namespace test

namespace {

using test::ZTestOptions;
using test::ZTestReport;

using test::settings_for;

RenderResult render_analytic(const Scene& s, int threads = 0) {
  CpuRenderer r(threads);
  return r.render(s, settings_for(s), {});
}

bool all_finite(const RenderResult& r) {
  for (double v : r.sum)
    if (!std::isfinite(v)) return false;
  for (double v : r.sum_sq)
    if (!std::isfinite(v)) return false;
  return true;
}

// Absorption-estimator samples are Le or background (Bernoulli-like): pooled
// (Stats.h explains).
using test::pooled;

// The closed-form pixel means are quadrature; a finer quadrature must agree far
// below the render's standard errors, or the z-tests above would test it instead.
TEST(CpuAnalytic, AnalyticQuadratureConverged) {
  for (const Scene& s : {test::absorbing_sphere_scene(), test::absorbing_box_scene()}) {
    test::PixelStats ps = test::pixel_stats(render_analytic(s), true);  // the SE the z-test uses
    auto coarse = test::single_collision_exact(s);
    auto fine = test::single_collision_exact(s, 12, 7, 0.025);
    double worst = 0.0;
    for (int y = 0; y < ps.height; ++y)
      for (int x = 0; x < ps.width; ++x)
        for (int c = 0; c < 3; ++c) {
          double d = std::abs(coarse(x, y)[c] - fine(x, y)[c]);
          double se = ps.se[(size_t(y) * ps.width + x) * 3 + c];
          EXPECT_LE(d, 0.1 * se + 1e-12) << "pixel " << x << "," << y << " channel " << c;
          if (se > 0) worst = std::max(worst, d / se);
        }
    std::printf("quadrature: max |coarse - fine| / SE = %.4f\n", worst);
  }
}

// Scene (c), the CPU-vs-GPU scene: two CPU renders with different seeds agree
// (ztest_images accepts a correct pair), while flipping the sign of every HG g
// (the classic convention mistake) is detected at the same spp.
TEST(CpuAnalytic, ChromaticScatteringSelfConsistentAndSensitiveToG) {
  Scene s = test::chromatic_scattering_scene();
  RenderResult a = render_analytic(s);
  Scene s2 = s;
  s2.film.seed = 12345;
  RenderResult b = render_analytic(s2);
  EXPECT_EQ(a.nonfinite_samples, 0u);
  ZTestReport same = test::ztest_images(a, b, pooled());
  EXPECT_TRUE(same.ok) << same.summary();
  std::printf("%s\n", same.summary().c_str());
  for (Medium& m : s2.media) m.g = -m.g;
  ZTestReport flipped = test::ztest_images(render_analytic(s2), a, pooled());
  EXPECT_FALSE(flipped.ok) << flipped.summary();
  std::printf("g flipped: %s\n", flipped.summary().c_str());
}

// emission.temperature_k: Le = scale × color::blackbody_rgb(T, mode, observer,
// adapt_to_k); equilibrium makes the pixel value exactly that.
TEST(CpuAnalytic, BlackbodyEmissionInEquilibrium) {
  Scene s = test::equilibrium_sphere_scene(8, 8, 64);
  Emission& e = s.media[0].emission;
  e.rgb.reset();
  e.temperature_k = 1800.0;
  e.scale = 3.0;
  e.blackbody = BlackbodyMode::Seed;
  glm::dvec3 Le = 3.0 * color::blackbody_rgb(1800.0, BlackbodyMode::Seed, 2, std::nullopt);
  ASSERT_GT(Le.r, 0.0);
  ZTestReport rep = test::ztest_against_exact(render_analytic(s), [&](int, int) { return Le; });
  EXPECT_TRUE(rep.ok) << rep.summary();
}

// The tests can fail: a 2 % brighter "exact" emission is rejected.
TEST(CpuAnalytic, ZTestRejectsWrongExact) {
  Scene s = test::absorbing_sphere_scene();
  RenderResult r = render_analytic(s);
  Scene wrong = s;
  wrong.media[0].emission.scale *= 1.02;
  ZTestReport rep = test::ztest_against_exact(r, test::single_collision_exact(wrong), pooled());
  EXPECT_FALSE(rep.ok) << rep.summary();
  EXPECT_FALSE(rep.bias_ok) << rep.summary();
  // And a mirrored image (x flipped) fails per pixel.
  auto exact = test::single_collision_exact(s);
  ZTestReport mirrored =
      test::ztest_against_exact(r, [&](int x, int y) { return exact(r.width - 1 - x, y); }, pooled());
  EXPECT_FALSE(mirrored.fraction_ok) << mirrored.summary();
}

// Image x grows along cross(forward, up), y grows downwards (docs/scene-format.md "camera"), checked
// without the test-side camera model.
TEST(CpuAnalytic, CameraOrientation) {
  Scene s = test::analytic_base_scene(32, 32, 4);
  glm::dvec3 f = glm::normalize(s.camera.look_at - s.camera.position);
  glm::dvec3 right = glm::normalize(glm::cross(f, s.camera.up));
  s.media.push_back(test::homogeneous_sphere("b", right * 1.0 + glm::dvec3(0, 1.0, 0), 0.4, {50, 50, 50},
                                             {0, 0, 0}, 0.0, glm::dvec3(1.0)));
  RenderResult r = render_analytic(s);
  double cx = 0, cy = 0, w = 0;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      double v = r.sum[(size_t(y) * r.width + x) * 3];
      cx += v * (x + 0.5);
      cy += v * (y + 0.5);
      w += v;
    }
  ASSERT_GT(w, 0.0);
  EXPECT_GT(cx / w, 0.6 * r.width);   // right half
  EXPECT_LT(cy / w, 0.4 * r.height);  // top half
}

TEST(CpuRenderer, DeterministicAcrossThreadCounts) {
  Scene s = test::chromatic_scattering_scene(24, 20, 8);
  RenderResult a = render_analytic(s, 1), b = render_analytic(s, 2), c = render_analytic(s, 3);
  ASSERT_EQ(a.sum.size(), b.sum.size());
  EXPECT_TRUE(a.sum == b.sum && a.sum_sq == b.sum_sq);
  EXPECT_TRUE(a.sum == c.sum && a.sum_sq == c.sum_sq);
  EXPECT_EQ(a.events, b.events);
  // A different seed or frame changes the image.
  RenderSettings rs = settings_for(s);
  rs.frame = 1;
  EXPECT_FALSE(CpuRenderer(2).render(s, rs, {}).sum == a.sum);
}

TEST(CpuRenderer, GrazingAndBoundaryRaysStayFinite) {
  // Camera on a sphere's surface and on a box's face plane, looking along the
  // tangent plane: half the rays skim the boundary; plus a distant sphere whose
  // silhouette many rays graze.
  Scene s = test::analytic_base_scene(32, 32, 16);
  s.camera.position = {0, 0, -1};
  s.camera.look_at = {1, 0, -1};
  s.background = {0.1, 0.2, 0.3};
  s.media.push_back(test::homogeneous_sphere("s", {0, 0, 0}, 1.0, {1, 2, 3}, {1, 1, 1}, 0.9, glm::dvec3(1.0)));
  s.media.push_back(test::homogeneous_box("b", {-2, -1, -1}, {2, 1, 0}, {0.5, 0.5, 0.5}, {2, 2, 2}, -0.9,
                                          glm::dvec3(0.5)));
  s.media.push_back(test::homogeneous_sphere("far", {3, 0, -1}, 1e-3, {1e6, 1e6, 1e6}, {0, 0, 0}, 0.0,
                                             glm::dvec3(1.0)));
  RenderResult r = render_analytic(s);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  EXPECT_TRUE(all_finite(r));
  // Extreme coefficients: near-zero and huge σ, |g| tiny and near 1.
  s.media[0].sigma_s = {1e-12, 0, 1e8};
  s.media[0].g = 1e-9;
  s.media[1].g = 0.999999;
  r = render_analytic(s);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  EXPECT_TRUE(all_finite(r));
}

TEST(CpuRenderer, ProgressCancelAndTimeLimit) {
  Scene s = test::absorbing_sphere_scene(16, 16, 64);
  CpuRenderer cpu(2);
  EXPECT_EQ(cpu.name(), "cpu");
  EXPECT_NE(cpu.device_name().find("CPU reference (2 threads)"), std::string::npos);
  std::vector<int> seen;
  RenderControl ctl;
  ctl.progress = [&](int done, int target) {
    EXPECT_EQ(target, 64);
    seen.push_back(done);
  };
  RenderResult full = cpu.render(s, settings_for(s), ctl);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 64);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_FALSE(full.cancelled);
  EXPECT_EQ(full.backend, "cpu");
  EXPECT_GE(full.seconds, 0.0);

  std::atomic<bool> cancel{true};
  RenderControl stop;
  stop.cancel = &cancel;
  RenderResult part = cpu.render(s, settings_for(s), stop);
  EXPECT_TRUE(part.cancelled);
  EXPECT_GT(part.spp, 0);
  EXPECT_LT(part.spp, 64);
  // The partial render's sums are a prefix of the full one's samples: the first
  // pass of the full render gives exactly the same numbers.
  RenderSettings first = settings_for(s);
  first.spp = part.spp;
  EXPECT_TRUE(cpu.render(s, first, {}).sum == part.sum);

  RenderSettings limited = settings_for(s);
  limited.spp = 1 << 20;
  limited.time_limit = 0.05;
  RenderResult timed = cpu.render(s, limited, {});
  EXPECT_FALSE(timed.cancelled);
  EXPECT_LT(timed.spp, limited.spp);
  EXPECT_GT(timed.spp, 0);
}

}  // namespace
}  // namespace pyrolume
