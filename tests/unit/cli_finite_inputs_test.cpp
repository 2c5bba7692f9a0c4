// Values beyond what the renderers can carry are refused at load (exit 2, one
// line naming the file and the key) or rendered finite, on the CPU reference
// (docs/robustness.md "Finite by construction"; the cases:
// tests/support/FiniteInputs.h, the Vulkan half: tests/vulkan/cli_finite_inputs_vulkan_test.cpp).
#include "support/FiniteInputs.h"

namespace pyrolume {
namespace {
using namespace pyrolume::test;
namespace fs = std::filesystem;

TEST(CliFiniteInputs, ValuesBeyondFloatAreRefusedNamingTheKey) {
  auto dir = temp_dir("finite-refused");
  write_finite_inputs(dir);
  for (const FiniteCase& c : refused_finite_cases(dir)) expect_finite_case_refused(dir, c, "cpu");
  fs::remove_all(dir);
}

TEST(CliFiniteInputs, ExtremeButRepresentableValuesRenderFinite) {
  auto dir = temp_dir("finite-rendered");
  write_finite_inputs(dir);
  expect_overflowing_plane_normal_renders(dir, "cpu");
  // Wider than any GPU's 2D texture side: the CPU reference renders it.
  write_file(dir / "w.json", "{" + std::string(kFiniteFilm) + R"(, "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "wide.png"}}}]})");
  CliResult r = run_cli("render " + q(dir / "w.json") + " -o " + q(dir / "o.exr") + " --backend cpu");
  EXPECT_EQ(r.status, 0) << r.err;
  fs::remove_all(dir);
}

TEST(CliFiniteInputs, SamplesBeyondTheRadianceBoundAreCountedNotAccumulated) {
  auto dir = temp_dir("finite-bound");
  expect_samples_beyond_the_bound_counted(dir, "cpu");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
