// Next-event estimation and MIS in the CPU reference (docs/mis.md): MIS,
// BSDF/phase sampling only and light sampling only converge to the same image
// (z-tests, with and without surfaces and sky), furnaces stay exactly 1 with
// the sky sampled as a light, and MIS lowers the noise where the fire lights a
// surface.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/cpu/CpuRenderer.h"
#include "scene/MediumVolume.h"
#include "support/MisScenes.h"
#include "support/Stats.h"

namespace pyrolume {
namespace {

using test::Strategy;
using test::ZTestOptions;
using test::ZTestReport;

RenderResult render(const Scene& s) {
  CpuRenderer r(0);
  RenderResult res = r.render(s, test::settings_for(s), {});
  EXPECT_EQ(r.majorant_violations(), 0u);
  EXPECT_EQ(res.nonfinite_samples, 0u);
  test::expect_strategy_as_written(s, res);
  return res;
}

// Terrain-like: an absorbing fire over a plane under a sky. All three
// strategies have finite variance here.
TEST(CpuMis, FireOverPlaneWithSkyStrategiesAgree) {
  test::expect_strategies_agree([](const Scene& s) { return render(s); }, test::temp_dir("cpu_mis_plane"), 1024, "");
}

// The fire scatters too: MIS at medium vertices inside the emitter.
TEST(CpuMis, ScatteringFireOverPlaneMisAgrees) {
  const auto dir = test::temp_dir("cpu_mis_plane");
  auto scene = [&](Strategy k, int spp) { return test::fire_over_plane_scene(dir, k, true, true, 24, 18, spp); };
  test::expect_same_image(render(scene(Strategy::Mis, 256)), render(scene(Strategy::Bsdf, 1024)), 0.02, "MIS vs BSDF only");
}

TEST(CpuMis, ScatteringEmissiveMediumMisAgrees) {
  const auto dir = test::temp_dir("cpu_mis_scattering");
  RenderResult bsdf = render(test::scattering_fire_scene(dir, Strategy::Bsdf, 12, 12, 8192));
  RenderResult mis = render(test::scattering_fire_scene(dir, Strategy::Mis, 12, 12, 4096));
  test::expect_same_image(mis, bsdf, 0.02, "MIS vs phase only");
}

// The fire lights the plane: at equal spp, MIS has far less variance on plane
// pixels than BSDF sampling, which must hit the small box by chance (measured
// 17–130× by row; the bar for terrain_explosion is 4×).
TEST(CpuMis, MisLowersVarianceOnLitPlane) {
  const auto dir = test::temp_dir("cpu_mis_plane");
  Scene s_bsdf = test::fire_over_plane_scene(dir, Strategy::Bsdf, false, false, 24, 18, 64);
  RenderResult bsdf = render(s_bsdf);
  RenderResult mis = render(test::fire_over_plane_scene(dir, Strategy::Mis, false, false, 24, 18, 64));
  // The bottom quarter: plane in front of the box, camera rays through no medium.
  const int first = s_bsdf.film.height * 3 / 4;
  const double v_bsdf = test::lower_rows_variance(bsdf, first), v_mis = test::lower_rows_variance(mis, first);
  std::printf("plane variance: BSDF %.4g, MIS %.4g, ratio %.1f\n", v_bsdf, v_mis, v_bsdf / v_mis);
  EXPECT_GT(v_bsdf, 4.0 * v_mis);
}

// A white diffuse sphere (albedo 1) in a uniform white sky is exactly 1
// everywhere, with the sky sampled as a light and combined by MIS.
TEST(CpuMis, FurnaceSphereIsOneWithSkyAsLight) {
  const auto dir = test::temp_dir("cpu_mis_furnace");
  for (Strategy k : {Strategy::Mis, Strategy::LightOnly})
    // n next-event samples per surface vertex; the last with the ratio-tracked continuation.
    for (auto [n, ratio] : {std::pair{1, false}, std::pair{3, false}, std::pair{3, true}}) {
      RenderResult r = render(test::furnace_sphere_scene(dir, k, n, ratio));
      ZTestReport z = test::ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); }, test::mis_pooled(0.01));
      EXPECT_TRUE(z.ok) << n << " light samples" << (ratio ? ", ratio-tracked continuation: " : ": ") << z.summary();
      std::printf("furnace, %d light samples%s: %s\n", n, ratio ? ", ratio-tracked continuation" : "",
                  z.summary().c_str());
    }
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
  RenderResult r = render(s);
  ZTestReport z = test::ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); }, test::mis_pooled(0.01));
  EXPECT_TRUE(z.ok) << z.summary();
}

// The furnace with smoke around the sphere (test::smoky_furnace_scene): the
// ratio-tracked continuation's rays cross the smoke before they reach the sky.
TEST(CpuMis, SmokyFurnaceIsOneWithRatioTrackedContinuation) {
  const auto dir = test::temp_dir("cpu_mis_furnace");
  for (bool ratio : {false, true}) {
    ZTestReport z = test::ztest_against_exact(render(test::smoky_furnace_scene(dir, Strategy::Mis, ratio)),
                                              [](int, int) { return glm::dvec3(1.0); }, test::mis_pooled(0.01));
    EXPECT_TRUE(z.ok) << (ratio ? "ratio-tracked continuation: " : "path continuation: ") << z.summary();
    std::printf("smoky furnace%s: %s\n", ratio ? ", ratio-tracked continuation" : "", z.summary().c_str());
  }
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
  absorption.integrator.emission_estimator = "absorption";
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
