// Next-event estimation and MIS on the Vulkan backend (docs/mis.md), validation
// layers on: GPU against the CPU reference with MIS (scattering fire over a
// plane under a sky, an emissive scattering grid, chromatic σ for the spectral
// MIS pdfs), MIS / BSDF only / light only agreeing on the GPU, a furnace with
// the sky as a light, and the variance MIS saves on the lit plane.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "render/cpu/CpuRenderer.h"
#include "support/MisScenes.h"
#include "support/Stats.h"
#include "support/VulkanFixture.h"

namespace pyrolume {
namespace {

using test::Strategy;
using test::ZTestOptions;
using test::ZTestReport;

class VulkanMis : public test::VulkanFixture {
 protected:
  RenderResult gpu(const Scene& s) {
    RenderResult r = backend_->render(s, test::settings_for(s), {});
    EXPECT_EQ(r.nonfinite_samples, 0u);
    test::expect_strategy_as_written(s, r);
    return r;
  }
  RenderResult cpu(const Scene& s, int spp) {
    Scene c = s;
    c.film.spp = spp;
    CpuRenderer renderer(0);
    RenderResult r = renderer.render(c, test::settings_for(c), {});
    EXPECT_EQ(renderer.majorant_violations(), 0u);
    test::expect_strategy_as_written(c, r);
    return r;
  }
};

TEST_F(VulkanMis, ScatteringFireOverPlaneMatchesCpu) {
  const auto dir = test::temp_dir("vk_mis_plane");
  Scene s = test::fire_over_plane_scene(dir, Strategy::Mis, true, true, 24, 18, 512);
  test::expect_same_image(gpu(s), cpu(s, 512), 0.02, "GPU vs CPU, MIS");
}

TEST_F(VulkanMis, ChromaticFireOverPlaneMatchesCpu) {
  const auto dir = test::temp_dir("vk_mis_plane");
  Scene s = test::fire_over_plane_scene(dir, Strategy::Mis, true, true, 24, 18, 512);
  s.media[0].sigma_a = {1.0, 2.0, 3.5};
  s.media[0].sigma_s = {2.5, 1.5, 0.5};
  test::expect_same_image(gpu(s), cpu(s, 512), 0.02, "GPU vs CPU, MIS, chromatic sigma");
}

TEST_F(VulkanMis, EmissiveScatteringGridMatchesCpu) {
  const auto dir = test::temp_dir("vk_mis_scattering");
  Scene s = test::scattering_fire_scene(dir, Strategy::Mis, 12, 12, 4096);
  test::expect_same_image(gpu(s), cpu(s, 4096), 0.02, "GPU vs CPU, MIS, scattering emitter");
}

TEST_F(VulkanMis, StrategiesAgreeOnGpu) {
  test::expect_strategies_agree([this](const Scene& s) { return gpu(s); }, test::temp_dir("vk_mis_plane"), 2048,
                                "GPU ");
}

TEST_F(VulkanMis, FurnaceSphereIsOneWithSkyAsLight) {
  const auto dir = test::temp_dir("vk_mis_furnace");
  // Light only as well: a light ray lost on its way (as on llvmpipe once, see
  // next_light_ray) darkens it about 5x more than it darkens MIS.
  // n next-event samples per surface vertex; the last with the ratio-tracked continuation.
  for (auto [n, ratio] : {std::pair{1, false}, std::pair{3, false}, std::pair{3, true}}) {
    for (Strategy st : {Strategy::Mis, Strategy::LightOnly}) {
      const char* name = st == Strategy::Mis ? "MIS" : "light only";
      ZTestReport z = test::ztest_against_exact(gpu(test::furnace_sphere_scene(dir, st, n, ratio)),
                                                [](int, int) { return glm::dvec3(1.0); }, test::pooled(0.01));
      EXPECT_TRUE(z.ok) << n << " light samples" << (ratio ? ", ratio-tracked continuation, " : ", ") << name << ": "
                        << z.summary();
      std::printf("GPU furnace, %d light samples%s, %s: %s\n", n, ratio ? ", ratio-tracked continuation" : "", name,
                  z.summary().c_str());
    }
  }
}

// The furnace with smoke around the sphere (test::smoky_furnace_scene), MIS
// and light only, with the ratio-tracked continuation.
TEST_F(VulkanMis, SmokyFurnaceIsOneWithRatioTrackedContinuation) {
  const auto dir = test::temp_dir("vk_mis_furnace");
  for (Strategy st : {Strategy::Mis, Strategy::LightOnly}) {
    const char* name = st == Strategy::Mis ? "MIS" : "light only";
    ZTestReport z = test::ztest_against_exact(gpu(test::smoky_furnace_scene(dir, st, true)),
                                              [](int, int) { return glm::dvec3(1.0); }, test::pooled(0.01));
    EXPECT_TRUE(z.ok) << name << ": " << z.summary();
    std::printf("GPU smoky furnace, ratio-tracked continuation, %s: %s\n", name, z.summary().c_str());
  }
}

// Several next-event samples per surface vertex: the GPU's light-ray
// sequence and its MIS weights against the CPU reference's.
TEST_F(VulkanMis, SurfaceLightSamplesMatchCpu) {
  const auto dir = test::temp_dir("vk_mis_plane");
  Scene s = test::fire_over_plane_scene(dir, Strategy::Mis, true, true, 24, 18, 256);
  s.integrator.surface_light_samples = 3;
  test::expect_same_image(gpu(s), cpu(s, 256), 0.02, "GPU vs CPU, MIS, 3 light samples per surface vertex");
}

// Continuations drawn half from the lights (integrator.guided_continuation;
// docs/mis.md "Guided continuation"): GPU against the CPU reference.
TEST_F(VulkanMis, GuidedContinuationMatchesCpu) {
  const auto dir = test::temp_dir("vk_mis_plane");
  Scene s = test::fire_over_plane_scene(dir, Strategy::Mis, true, true, 24, 18, 256);
  s.integrator.guided_continuation = 0.5;
  test::expect_same_image(gpu(s), cpu(s, 256), 0.02, "GPU vs CPU, MIS, guided continuation");
}

// The ratio-tracked continuation (a light ray along the continuation, which
// then skips its first segment) on the scattering fire over a plane: GPU
// against the CPU reference.
TEST_F(VulkanMis, RatioTrackedContinuationMatchesCpu) {
  const auto dir = test::temp_dir("vk_mis_plane");
  Scene s = test::fire_over_plane_scene(dir, Strategy::Mis, true, true, 24, 18, 256);
  s.integrator.ratio_tracked_continuation = true;
  test::expect_same_image(gpu(s), cpu(s, 256), 0.02, "GPU vs CPU, MIS, ratio-tracked continuation");
}

// The automatic choice (integrator.mis absent, emission_estimator "auto";
// docs/mis.md "When light sampling runs by default") resolves the same on
// both backends: what each render reports, for a fire alone, a fire over a
// plane, the fire under a sky, and the fire alone with "mis": true.
TEST_F(VulkanMis, AutomaticChoiceIsTheSameOnBothBackends) {
  const auto dir = test::temp_dir("vk_mis_auto");
  auto automatic = [](Scene s) {
    s.integrator.mis.reset();
    s.integrator.emission_estimator = "auto";
    return s;
  };
  const Scene alone = automatic(test::scattering_fire_scene(dir, Strategy::Bsdf, 8, 8, 2));
  Scene sky = alone;
  sky.environment = Environment{test::write_uniform_sky(dir, glm::vec3(0.3f)), 1.0, 0.0};
  Scene asked = alone;
  asked.integrator.mis = true;
  struct Case {
    const char* what;
    Scene scene;
    const char* strategy;
    const char* estimator;
  };
  const Case cases[] = {
      {"fire alone", alone, "bsdf", "absorption"},
      {"fire over a plane", automatic(test::fire_over_plane_scene(dir, Strategy::Bsdf, false, true, 8, 8, 2)), "mis",
       "collision"},
      {"fire under a sky", sky, "mis", "collision"},
      {"fire alone, mis true", asked, "mis", "collision"},
  };
  for (const Case& c : cases) {
    const RenderResult g = gpu(c.scene), r = cpu(c.scene, 2);
    EXPECT_EQ(g.light_strategy, c.strategy) << c.what;
    EXPECT_EQ(g.emission_estimator, c.estimator) << c.what;
    EXPECT_EQ(r.light_strategy, g.light_strategy) << c.what;
    EXPECT_EQ(r.emission_estimator, g.emission_estimator) << c.what;
  }
}

// Under a sky without surfaces the automatic choice samples the map but not
// the emissive grid (probability 0 on both backends): the emission the walk
// finds in the grid is weighed against the map's pdf only. GPU against the
// CPU reference.
TEST_F(VulkanMis, SkySampledGridNotMatchesCpu) {
  const auto dir = test::temp_dir("vk_mis_auto_sky");
  Scene s = test::scattering_fire_scene(dir, Strategy::Bsdf, 12, 12, 2048);
  s.integrator.mis.reset();
  s.integrator.emission_estimator = "auto";
  s.environment = Environment{test::write_uniform_sky(dir, glm::vec3(0.3f, 0.4f, 0.6f)), 1.0, 0.0};
  const RenderResult g = gpu(s);
  ASSERT_EQ(g.light_strategy, "mis");
  test::expect_same_image(g, cpu(s, 2048), 0.02, "GPU vs CPU, automatic: the sky sampled, the grid not");
}

TEST_F(VulkanMis, MisLowersVarianceOnLitPlane) {
  const auto dir = test::temp_dir("vk_mis_plane");
  Scene sb = test::fire_over_plane_scene(dir, Strategy::Bsdf, false, false, 24, 18, 64);
  RenderResult bsdf = gpu(sb);
  RenderResult mis = gpu(test::fire_over_plane_scene(dir, Strategy::Mis, false, false, 24, 18, 64));
  const int first = sb.film.height * 3 / 4;
  const double vb = test::lower_rows_variance(bsdf, first), vm = test::lower_rows_variance(mis, first);
  std::printf("GPU plane variance: BSDF %.4g, MIS %.4g, ratio %.1f\n", vb, vm, vb / vm);
  EXPECT_GT(vb, 4.0 * vm);
}

}  // namespace
}  // namespace pyrolume
