// The Vulkan half of tests/unit/cli_finite_inputs_test.cpp (cases:
// tests/support/FiniteInputs.h): the same refusals through the GPU's loaders,
// the same finite renders, and a texture past the device's 2D limit refused
// naming the file.
#include "support/FiniteInputs.h"

namespace pyrolume {
namespace {
using namespace pyrolume::test;
namespace fs = std::filesystem;

TEST(CliFiniteInputsVulkan, ValuesBeyondFloatAreRefusedNamingTheKey) {
  auto dir = temp_dir("finite-refused-vk");
  write_finite_inputs(dir);
  for (const FiniteCase& c : refused_finite_cases(dir)) expect_finite_case_refused(dir, c, "vulkan");
  fs::remove_all(dir);
}

TEST(CliFiniteInputsVulkan, ExtremeButRepresentableValuesRenderFinite) {
  auto dir = temp_dir("finite-rendered-vk");
  write_finite_inputs(dir);
  expect_overflowing_plane_normal_renders(dir, "vulkan");
  // 65536 x 1 texels: past lavapipe's (and most GPUs') 16384 per side. A
  // device limit, named with the file (it used to be an internal error, exit 1).
  write_file(dir / "w.json", "{" + std::string(kFiniteFilm) + R"(, "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "wide.png"}}}]})");
  CliResult r = run_cli("render " + q(dir / "w.json") + " -o " + q(dir / "v.exr") + " --backend vulkan");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find((dir / "wide.png").string() + ": 65536 x 1 texels exceed this device's 2D texture limit"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "v.exr"));
  fs::remove_all(dir);
}

TEST(CliFiniteInputsVulkan, SamplesBeyondTheRadianceBoundAreCountedNotAccumulated) {
  auto dir = temp_dir("finite-bound-vk");
  expect_samples_beyond_the_bound_counted(dir, "vulkan");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
