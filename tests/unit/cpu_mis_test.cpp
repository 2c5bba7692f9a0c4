// Next-event estimation and MIS in the CPU reference (docs/mis.md): the cases
// both backends share run from tests/support/MisSuite.h (Mis.*/"cpu"); here,
// the CPU-only ones: MIS and BSDF/phase sampling only converge to the same
// image with a scattering emitter, a scattering furnace stays 1 with the sky
// as a light, and the light choice and strategy rules.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/cpu/CpuRenderer.h"
#include "support/MisSuite.h"
#include "scene/MediumVolume.h"
#include "support/Stats.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Mis, "cpu");
}  // namespace test

namespace {

using test::Strategy;
using test::ZTestOptions;
using test::ZTestReport;

RenderResult render_mis(const Scene& s) {
  CpuRenderer r(0);
  RenderResult res = r.render(s, test::settings_for(s), {});
  EXPECT_EQ(r.majorant_violations(), 0u);
  EXPECT_EQ(res.nonfinite_samples, 0u);
  test::expect_strategy_as_written(s, res);
  return res;
}

// The fire scatters too: MIS at medium vertices inside the emitter.
TEST(CpuMis, ScatteringFireOverPlaneMisAgrees) {
  const auto dir = test::temp_dir("cpu_mis_plane");
  auto scene = [&](Strategy k, int spp) { return test::fire_over_plane_scene(dir, k, true, true, 24, 18, spp); };
  test::expect_same_image(render_mis(scene(Strategy::Mis, 256)), render_mis(scene(Strategy::Bsdf, 1024)), 0.02, "MIS vs BSDF only");
}

TEST(CpuMis, ScatteringEmissiveMediumMisAgrees) {
  const auto dir = test::temp_dir("cpu_mis_scattering");
  RenderResult bsdf = render_mis(test::scattering_fire_scene(dir, Strategy::Bsdf, 12, 12, 8192));
  RenderResult mis = render_mis(test::scattering_fire_scene(dir, Strategy::Mis, 12, 12, 4096));
  test::expect_same_image(mis, bsdf, 0.02, "MIS vs phase only");
}

// A purely scattering medium (σa = 0) in a uniform white sky: energy is
// conserved, L = 1, with next-event estimation through the medium.
TEST(CpuMis, ScatteringFurnaceIsOneWithSkyAsLight) {
  const auto dir = test::temp_dir("cpu_mis_furnace");
  Scene s = test::analytic_base_scene(16, 16, 64);
  s.integrator.max_depth = 1000;
  s.media.push_back(test::homogeneous_sphere("smoke", {0, 0, 0}, 1.0, glm::dvec3(0.0), glm::dvec3(3.0), 0.5,
                                             std::nullopt));
  s.environment = Environment{test::write_uniform_sky(dir, glm::vec3(1.0f)), 1.0, 0.0};
  test::set_strategy(s, Strategy::Mis);
  RenderResult r = render_mis(s);
  ZTestReport z = test::ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); }, test::pooled(0.01));
  EXPECT_TRUE(z.ok) << z.summary();
}

// Light choice and strategy rules (host/light/LightSelection.h).
TEST(LightSelection, ProbabilitiesAndStrategies) {
  const auto dir = test::temp_dir("cpu_mis_select");
  Scene s = test::fire_over_plane_scene(dir, Strategy::Mis, true, true);
  const EnvironmentMap env = EnvironmentMap::load(s.environment->file);
  const StoredVolume vol = load_stored_volume(s.media[0]);
  const EmissionCdf cdf = EmissionCdf::build(s.media[0], vol);
  ASSERT_FALSE(cdf.empty());
  // Two emissive grids of equal power share the media's half equally.
  LightSelection l = select_lights(s, &env, {&cdf, &cdf});
  EXPECT_EQ(l.strategy, LightStrategy::Mis);
  EXPECT_DOUBLE_EQ(l.p_continue_own, kContinueOwn);  // continuations guided toward the lights
  EXPECT_DOUBLE_EQ(l.p_env, 0.5);
  EXPECT_DOUBLE_EQ(l.p_medium[0], 0.25);
  EXPECT_DOUBLE_EQ(l.p_medium[1], 0.25);
  // No environment: the media take everything; no media: the environment does.
  l = select_lights(s, nullptr, {&cdf, nullptr});
  EXPECT_DOUBLE_EQ(l.p_env, 0.0);
  EXPECT_DOUBLE_EQ(l.p_medium[0], 1.0);
  l = select_lights(s, &env, {nullptr});
  EXPECT_DOUBLE_EQ(l.p_env, 1.0);
  // Nothing to sample, mis off, the absorption estimator or max_depth 0: BSDF only.
  EXPECT_EQ(select_lights(s, nullptr, {nullptr}).strategy, LightStrategy::Bsdf);
  Scene off = s;
  off.integrator.mis = false;
  EXPECT_EQ(select_lights(off, &env, {&cdf}).strategy, LightStrategy::Bsdf);
  EXPECT_DOUBLE_EQ(select_lights(off, &env, {&cdf}).p_continue_own, 1.0);  // BSDF sampling only
  Scene absorption = s;
  absorption.integrator.mis.reset();  // "mis": true with absorption is refused (light_selection_test)
  absorption.integrator.emission_estimator = EmissionEstimator::Absorption;
  EXPECT_EQ(select_lights(absorption, &env, {&cdf}).strategy, LightStrategy::Bsdf);
  Scene depth0 = s;
  depth0.integrator.max_depth = 0;
  EXPECT_EQ(select_lights(depth0, &env, {&cdf}).strategy, LightStrategy::Bsdf);
  Scene light_only = s;
  light_only.integrator.light_only = true;
  EXPECT_EQ(select_lights(light_only, &env, {&cdf}).strategy, LightStrategy::LightOnly);
  // Without light sampling no light has a probability (both backends' pdfs agree).
  for (const Scene* bsdf : {&off, &absorption, &depth0}) {
    const LightSelection b = select_lights(*bsdf, &env, {&cdf});
    EXPECT_DOUBLE_EQ(b.p_env, 0.0);
    EXPECT_DOUBLE_EQ(b.p_medium[0], 0.0);
  }
}

}  // namespace
}  // namespace pyrolume
