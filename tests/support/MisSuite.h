#pragma once
// Next-event estimation and MIS (docs/mis.md) on either backend: MIS, BSDF
// only and light only agree on the fire over a plane under a sky, furnaces
// stay 1 with the sky sampled as a light, and MIS lowers the noise where the
// fire lights a surface. One body per case, instantiated for the CPU
// reference by tests/unit/cpu_mis_test.cpp and for Vulkan by
// tests/vulkan/vulkan_mis_test.cpp (BackendSuite.h explains); the cases only
// one backend has (the GPU's comparisons with the CPU reference among them)
// stay in those files.
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/BackendSuite.h"
#include "support/MisScenes.h"
#include "support/Stats.h"
#include "support/TestSupport.h"

namespace pyrolume::test {

class MisFixture : public BackendFixture {
 protected:
  using BackendFixture::BackendFixture;

  // render(), and the strategy the scene asks for is the one used.
  RenderResult render_as_written(const Scene& s) {
    RenderResult r = render(s);
    expect_strategy_as_written(s, r);
    return r;
  }
};

using Mis = BackendSuite<MisFixture>;

// Terrain-like: an absorbing fire over a plane under a sky. All three
// strategies have finite variance here (BSDF only at more spp on the GPU,
// whose per-sample cost is lower).
TEST_P(Mis, StrategiesAgreeOnFireOverPlaneWithSky) {
  expect_strategies_agree([this](const Scene& s) { return render_as_written(s); },
                          temp_dir(backend_name() + "_mis_plane"), per_backend(1024, 2048), backend_name() + " ");
}

// A white diffuse sphere (albedo 1) in a uniform white sky is exactly 1
// everywhere, with the sky sampled as a light and combined by MIS, and with
// light sampling only (a light ray lost on its way, as on llvmpipe once, see
// next_light_ray, darkens it about 5x more than it darkens MIS).
TEST_P(Mis, FurnaceSphereIsOneWithSkyAsLight) {
  const auto dir = temp_dir(backend_name() + "_mis_furnace");
  for (Strategy st : {Strategy::Mis, Strategy::LightOnly})
    // n next-event samples per surface vertex; the last with the ratio-tracked continuation.
    for (auto [n, ratio] : {std::pair{1, false}, std::pair{3, false}, std::pair{3, true}}) {
      const char* name = st == Strategy::Mis ? "MIS" : "light only";
      ZTestReport z = ztest_against_exact(render_as_written(furnace_sphere_scene(dir, st, n, ratio)),
                                          [](int, int) { return glm::dvec3(1.0); }, pooled(0.01));
      EXPECT_TRUE(z.ok) << n << " light samples" << (ratio ? ", ratio-tracked continuation, " : ", ") << name << ": "
                        << z.summary();
      std::printf("%s furnace, %d light samples%s, %s: %s\n", backend_name().c_str(), n,
                  ratio ? ", ratio-tracked continuation" : "", name, z.summary().c_str());
    }
}

// The furnace with smoke around the sphere (smoky_furnace_scene): the
// ratio-tracked continuation's rays cross the smoke before they reach the
// sky. Per backend: the CPU checks MIS with the path and the ratio-tracked
// continuation, the GPU the ratio-tracked continuation with MIS and with
// light sampling only.
TEST_P(Mis, SmokyFurnaceIsOneWithRatioTrackedContinuation) {
  const auto dir = temp_dir(backend_name() + "_mis_furnace");
  const std::vector<std::pair<Strategy, bool>> cases =
      per_backend(std::vector<std::pair<Strategy, bool>>{{Strategy::Mis, false}, {Strategy::Mis, true}},
                  std::vector<std::pair<Strategy, bool>>{{Strategy::Mis, true}, {Strategy::LightOnly, true}});
  for (const auto& [st, ratio] : cases) {
    const char* name = st == Strategy::Mis ? "MIS" : "light only";
    ZTestReport z = ztest_against_exact(render_as_written(smoky_furnace_scene(dir, st, ratio)),
                                        [](int, int) { return glm::dvec3(1.0); }, pooled(0.01));
    EXPECT_TRUE(z.ok) << (ratio ? "ratio-tracked continuation, " : "path continuation, ") << name << ": "
                      << z.summary();
    std::printf("%s smoky furnace%s, %s: %s\n", backend_name().c_str(), ratio ? ", ratio-tracked continuation" : "",
                name, z.summary().c_str());
  }
}

// The fire lights the plane: at equal spp, MIS has far less variance on plane
// pixels than BSDF sampling, which must hit the small box by chance (measured
// 17–130× by row on the CPU; the bar for terrain_explosion is 4×).
TEST_P(Mis, MisLowersVarianceOnLitPlane) {
  const auto dir = temp_dir(backend_name() + "_mis_plane");
  Scene s_bsdf = fire_over_plane_scene(dir, Strategy::Bsdf, false, false, 24, 18, 64);
  RenderResult bsdf = render_as_written(s_bsdf);
  RenderResult mis = render_as_written(fire_over_plane_scene(dir, Strategy::Mis, false, false, 24, 18, 64));
  // The bottom quarter: plane in front of the box, camera rays through no medium.
  const int first = s_bsdf.film.height * 3 / 4;
  const double v_bsdf = lower_rows_variance(bsdf, first), v_mis = lower_rows_variance(mis, first);
  std::printf("%s plane variance: BSDF %.4g, MIS %.4g, ratio %.1f\n", backend_name().c_str(), v_bsdf, v_mis,
              v_bsdf / v_mis);
  EXPECT_GT(v_bsdf, 4.0 * v_mis);
}

}  // namespace pyrolume::test
