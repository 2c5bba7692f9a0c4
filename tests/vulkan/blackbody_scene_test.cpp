// spheres_temperatures.json on the GPU against the CPU reference (issue 3):
// blackbody emission at 1000–10 000 K agrees per pixel and in total.
#include <gtest/gtest.h>

#include "backends/Backends.h"
#include "render/cpu/CpuRenderer.h"
#include "scene/Scene.h"
#include "support/Stats.h"

namespace pyrolume {
namespace {

TEST(BlackbodyScene, GpuMatchesCpuOnSpheresTemperatures) {
  Scene s = load_scene(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/scenes/spheres_temperatures.json");
  RenderSettings rs;
  rs.width = 126;
  rs.height = 42;
  rs.spp = 128;
  rs.seed = 7;
  BackendOptions o;
  o.validation = true;
  auto gpu = make_backend("vulkan", o);
  RenderResult a = gpu->render(s, rs, {});
  CpuRenderer cpu;
  RenderResult b = cpu.render(s, rs, {});
  test::ZTestOptions opt;
  opt.pool3x3 = true;
  test::ZTestReport rep = test::ztest_images(a, b, opt);
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("%s\n", rep.summary().c_str());
  EXPECT_EQ(gpu->validation_messages(), 0u);

  // Not a vacuous pass: a different blackbody mode on the CPU side is caught.
  for (auto& m : s.media) m.emission.blackbody = BlackbodyMode::Peak;
  RenderResult c = cpu.render(s, rs, {});
  EXPECT_FALSE(test::ztest_images(a, c, opt).ok);
}

}  // namespace
}  // namespace pyrolume
