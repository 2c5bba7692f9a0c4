// Values beyond what the renderers can carry are refused at load (exit 2, one
// line naming the file and the key) or rendered finite, on the CPU reference
// (docs/robustness.md "Finite by construction"; the cases:
// tests/support/FiniteInputs.h, the Vulkan half: tests/vulkan/cli_finite_inputs_vulkan_test.cpp).
#include "support/FiniteInputs.h"

namespace pyrolume::test {
namespace {

TEST(CliFiniteInputs, ValuesBeyondFloatAreRefusedNamingTheKey) { expect_finite_cases_refused("cpu"); }

TEST(CliFiniteInputs, ExtremeButRepresentableValuesRenderFinite) {
  expect_overflowing_plane_normal_renders("cpu");
  const CliResult r = render_wide_texture("cpu");  // the CPU reference has no texture size limit
  EXPECT_EQ(r.status, 0) << r.err;
}

// docs/robustness.md "Analytic lights": each at the largest accepted values
// lights the plane, finite, with no sample dropped.
TEST(CliFiniteInputs, LightsAtTheLargestAcceptedValuesRenderFinite) { expect_extreme_lights_render_finite("cpu"); }

TEST(CliFiniteInputs, SamplesBeyondTheRadianceBoundAreCountedNotAccumulated) {
  expect_samples_beyond_the_bound_counted("cpu");
}

}  // namespace
}  // namespace pyrolume::test
