// film.aovs on the Vulkan backend: the shared bodies (tests/support/AovSuite.h),
// and each light layer against the CPU reference's, computed independently.
#include <cmath>
#include <cstdio>

#include "support/AovSuite.h"

namespace pyrolume::test {
INSTANTIATE_BACKEND_SUITE(Aovs, "vulkan");

namespace {

class VulkanAovs : public BackendFixture {
 protected:
  VulkanAovs() : BackendFixture("vulkan") {}
};

// Per layer and channel, the pixels' GPU − CPU differences: each has mean 0
// when the layers agree, and they are independent across pixels, so their
// image mean over its standard error (from their own spread) is a z-score.
TEST_F(VulkanAovs, EachLightLayerAgreesWithTheCpuReference) {
  const RenderResult gpu = render(aov_layers_scene(256, 41));
  RenderResult cpu;
  {
    const Scene s = aov_layers_scene(256, 42);
    cpu = cpu_renderer().render(s, settings_for(s), {});
  }
  const Image g = image_from_render(gpu, false), c = image_from_render(cpu, false);
  ASSERT_TRUE(g.has_aovs());
  ASSERT_TRUE(c.has_aovs());
  const char* names[4] = {"emission", "scatter", "surface", "background"};
  const std::vector<float>* gl[4] = {&g.aovs.emission, &g.aovs.scatter, &g.aovs.surface, &g.aovs.background};
  const std::vector<float>* cl[4] = {&c.aovs.emission, &c.aovs.scatter, &c.aovs.surface, &c.aovs.background};
  const size_t n = g.pixel_count();
  for (int k = 0; k < 4; ++k)
    for (int ch = 0; ch < 3; ++ch) {
      double sum = 0.0, sum_sq = 0.0, level = 0.0;
      for (size_t i = 0; i < n; ++i) {
        const double d = double((*gl[k])[i * 3 + ch]) - double((*cl[k])[i * 3 + ch]);
        sum += d;
        sum_sq += d * d;
        level += (*cl[k])[i * 3 + ch];
      }
      const double mean = sum / n, sd = std::sqrt(std::max(0.0, (sum_sq - sum * mean) / (n - 1)));
      const double z = sd > 0.0 ? mean / (sd / std::sqrt(double(n))) : (mean == 0.0 ? 0.0 : 1e9);
      std::printf("%-10s ch %d: image mean %.5g, GPU - CPU %.3g, z = %.2f\n", names[k], ch, level / n, mean, z);
      EXPECT_GT(level, 0.0) << names[k] << " is empty on the CPU";
      EXPECT_LT(std::abs(z), 4.0) << names[k] << " channel " << ch;
    }
}

}  // namespace
}  // namespace pyrolume::test
