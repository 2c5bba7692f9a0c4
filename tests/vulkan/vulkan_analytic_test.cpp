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
