// Next-event estimation and MIS on the Vulkan backend (docs/mis.md), validation
// layers on. The cases both backends share (strategies agreeing, furnaces
// with the sky as a light, the variance MIS saves on the lit plane) run from
// tests/support/MisSuite.h (Mis.*/"vulkan"); here, GPU against the CPU
// reference with MIS (scattering fire over a plane under a sky, an emissive
// scattering grid, chromatic σ for the spectral MIS pdfs, several light
// samples, guided and ratio-tracked continuations, the automatic choice).
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "render/cpu/CpuRenderer.h"
#include "support/MisSuite.h"
#include "support/Stats.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Mis, "vulkan");
}  // namespace test

namespace {

using test::Strategy;
using test::ZTestOptions;
using test::ZTestReport;

class VulkanMis : public test::MisFixture {
 protected:
  VulkanMis() : test::MisFixture("vulkan") {}

  RenderResult gpu(const Scene& s) { return render_as_written(s); }
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
    s.integrator.emission_estimator = std::nullopt;  // "auto"
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
  s.integrator.emission_estimator = std::nullopt;  // "auto"
  s.environment = Environment{test::write_uniform_sky(dir, glm::vec3(0.3f, 0.4f, 0.6f)), 1.0, 0.0};
  const RenderResult g = gpu(s);
  ASSERT_EQ(g.light_strategy, "mis");
  test::expect_same_image(g, cpu(s, 2048), 0.02, "GPU vs CPU, automatic: the sky sampled, the grid not");
}

}  // namespace
}  // namespace pyrolume
