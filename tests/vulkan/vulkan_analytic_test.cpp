// The Vulkan backend against closed forms and against the CPU reference
// (issue 2 tests), with validation layers on: any validation message fails.
// The closed-form cases both backends share run from
// tests/support/AnalyticSuite.h (Analytic.*/"vulkan"); here, the GPU-only ones.
#include <gtest/gtest.h>

#include "render/Backend.h"
#include "render/cpu/CpuRenderer.h"
#include "support/AccumulationChecks.h"
#include "support/AnalyticSuite.h"
#include "support/Stats.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Analytic, "vulkan");
}  // namespace test

namespace {

using test::settings_for;

// TimeLimitAndCancelStopEarly renders through vulkan_backend() directly:
// render() would insist on every sample asked for.
class VulkanAnalytic : public test::AnalyticFixture {
 protected:
  VulkanAnalytic() : test::AnalyticFixture("vulkan") {}
};

using test::pooled;

// Shader vs CPU on a scattering scene with chromatic sigma, g != 0 and two
// overlapping media: per-pixel z-test and the bias formula of docs/testing.md.
TEST_F(VulkanAnalytic, AgreesWithCpuReferenceOnChromaticScattering) {
  Scene s = test::chromatic_scattering_scene();
  RenderResult gpu = render(s);
  CpuRenderer cpu;
  RenderResult ref = cpu.render(s, settings_for(s), {});
  test::ZTestReport rep = test::ztest_images(gpu, ref, pooled());
  EXPECT_TRUE(rep.ok) << rep.summary();
  EXPECT_LE(rep.se_bias, 0.0025) << rep.summary();
  std::printf("%s\n", rep.summary().c_str());
}

// The test can fail: the same comparison against a CPU render with 3 % more
// emission is rejected.
TEST_F(VulkanAnalytic, ComparisonDetectsWrongEmission) {
  Scene s = test::chromatic_scattering_scene();
  RenderResult gpu = render(s);
  Scene brighter = s;
  for (auto& m : brighter.media) m.emission.scale *= 1.03;
  CpuRenderer cpu;
  test::ZTestReport rep = test::ztest_images(gpu, cpu.render(brighter, settings_for(s), {}), pooled());
  EXPECT_FALSE(rep.ok) << rep.summary();
}

// Film positions are stratified within each pixel (shaders/rng.glsl
// film_jitter): on pixels that a sharp edge cuts, the pixel mean varies across
// seeds far less than N independent positions would give (the sample
// variance over N, what the variance channel assumes). An opaque emissive box
// (L = Le inside, 0 outside) with a slanted edge across an 8×8 film.
TEST_F(VulkanAnalytic, FilmPositionsAreStratifiedWithinAPixel) {
  Scene s = test::analytic_base_scene(8, 8, 64);
  s.camera.position = {0.0, 0.0, -5.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.up = glm::normalize(glm::dvec3(0.3, 1.0, 0.0));  // the box's edge is slanted on the film
  s.media.push_back(test::homogeneous_box("edge", {-3.0, -3.0, -0.5}, {0.05, 3.0, 0.5}, glm::dvec3(1e3),
                                          glm::dvec3(0.0), 0.0, glm::dvec3(1.0), 1.0));
  constexpr int kSeeds = 16;
  const size_t n = size_t(s.film.width) * s.film.height;
  std::vector<double> mean_sum(n, 0.0), mean_sq(n, 0.0), iid_var(n, 0.0);
  for (int seed = 1; seed <= kSeeds; ++seed) {
    s.film.seed = uint32_t(seed);
    const RenderResult r = render(s);
    for (size_t p = 0; p < n; ++p) {
      const double N = r.spp, m = r.sum[3 * p] / N;
      mean_sum[p] += m;
      mean_sq[p] += m * m;
      iid_var[p] += std::max(0.0, r.sum_sq[3 * p] / N - m * m) / (N - 1.0) / kSeeds;
    }
  }
  double seen = 0.0, iid = 0.0;
  int cut = 0;
  for (size_t p = 0; p < n; ++p) {
    const double m = mean_sum[p] / kSeeds;
    if (!(m > 0.05 && m < 0.95)) continue;  // not on the edge
    ++cut;
    seen += (mean_sq[p] - kSeeds * m * m) / (kSeeds - 1.0);
    iid += iid_var[p];
  }
  ASSERT_GE(cut, 4) << "the edge should cut a column of pixels";
  std::printf("%d pixels on the edge: pixel-mean variance across seeds %.3g, independent positions would give %.3g\n",
              cut, seen, iid);
  EXPECT_LT(seen, 0.2 * iid);
}

TEST_F(VulkanAnalytic, RerunIsBitIdentical) {
  Scene s = test::chromatic_scattering_scene(16, 16, 32);
  RenderResult a = render(s), b = render(s);
  EXPECT_EQ(a.sum, b.sum);
  EXPECT_EQ(a.sum_sq, b.sum_sq);
  s.film.seed += 1;
  RenderResult c = render(s);
  EXPECT_NE(a.sum, c.sum);
}

TEST_F(VulkanAnalytic, TimeLimitAndCancelStopEarly) {
  Scene s = test::chromatic_scattering_scene(64, 64, 100000);
  RenderSettings rs = settings_for(s);
  test::CancelAfterPasses stop(2);
  RenderResult r = vulkan_backend().render(s, rs, stop.control);
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(stop.passes, 2);
  EXPECT_LT(r.spp, rs.spp);
  EXPECT_GT(r.spp, 0);
}

}  // namespace
}  // namespace pyrolume
