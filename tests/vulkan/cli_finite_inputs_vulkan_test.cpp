// The Vulkan half of tests/unit/cli_finite_inputs_test.cpp (cases:
// tests/support/FiniteInputs.h): the same refusals through the GPU's loaders,
// the same finite renders, and a texture past the device's 2D limit refused
// naming the file.
#include "support/FiniteInputs.h"

namespace pyrolume::test {
namespace {

TEST(CliFiniteInputsVulkan, ValuesBeyondFloatAreRefusedNamingTheKey) { expect_finite_cases_refused("vulkan"); }

TEST(CliFiniteInputsVulkan, ExtremeButRepresentableValuesRenderFinite) {
  expect_overflowing_plane_normal_renders("vulkan");
  // Past lavapipe's (and most GPUs') 16384 texels per side: a device limit,
  // named with the file (it used to be an internal error, exit 1).
  const CliResult r = render_wide_texture("vulkan");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("wide.png: 65536 x 1 texels exceed this device's 2D texture limit"), std::string::npos) << r.err;
}

// docs/robustness.md "Analytic lights": each at the largest accepted values
// lights the plane, finite, with no sample dropped.
TEST(CliFiniteInputsVulkan, LightsAtTheLargestAcceptedValuesRenderFinite) { expect_extreme_lights_render_finite("vulkan"); }

TEST(CliFiniteInputsVulkan, SamplesBeyondTheRadianceBoundAreCountedNotAccumulated) {
  expect_samples_beyond_the_bound_counted("vulkan");
}

}  // namespace
}  // namespace pyrolume::test
