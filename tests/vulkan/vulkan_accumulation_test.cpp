// The GPU accumulation (issue 10): Kahan-compensated float sums give constant
// radiance exactly at 65 536 spp (mean and Σ L²), the readback applies the
// compensation, non-finite samples are counted and recorded as 0, and a
// resumed render (state uploaded back to the device) is bit-identical to an
// uninterrupted one. Validation layers on.
#include <cstring>

#include <gtest/gtest.h>

#include "render/vulkan/RenderSession.h"
#include "shared/gpu_types.h"
#include "support/AccumulationChecks.h"
#include "support/VulkanFixture.h"

namespace pyrolume {
namespace {

class VulkanAccumulation : public test::VulkanFixture {};

TEST_F(VulkanAccumulation, ConstantBackgroundIsExactAt65536Spp) {
  // The values the device holds (float) are the exact ones.
  const glm::dvec3 bg(double(0.3f), double(0.7123f), double(1.1f));
  test::expect_constant_radiance_exact(*backend_, test::constant_background_scene(4, 4, 65536, bg), bg, 1e-6);
}

// (No equilibrium-medium twin of the CPU test: the GPU's emission estimator
// is unbiased there but not constant per sample, so Σ L²/n ≠ Le².)

// The readback is Σ = sum − compensation, evaluated in double: a texel whose
// float sum lost 2^-30 (kept in the compensation) reads back with it.
TEST_F(VulkanAccumulation, ReadbackAppliesTheKahanCompensation) {
  gpu::AccumTexel t{};
  t.sum = gpu::vec3(1.0f, 3.0f, 100.0f);
  t.events = 7.0f;
  t.sum_c = gpu::vec3(-std::ldexp(1.0f, -30), std::ldexp(1.0f, -28), 0.0f);
  t.events_c = -0.5f;
  t.sum_sq = gpu::vec3(2.0f, 9.0f, 1e4f);
  t.lookups = 11.0f;
  t.sum_sq_c = gpu::vec3(-std::ldexp(1.0f, -29), 0.0f, std::ldexp(1.0f, -20));
  t.nonfinite = 3.0f;
  AccumulationState st{"vulkan", 1, 1, 5, std::vector<uint8_t>(sizeof t)};
  std::memcpy(st.data.data(), &t, sizeof t);
  RenderResult r;
  RenderSession::result_from_state(st, r);
  EXPECT_EQ(r.spp, 5);
  EXPECT_EQ(r.sum[0], 1.0 + std::ldexp(1.0, -30));
  EXPECT_EQ(r.sum[1], 3.0 - std::ldexp(1.0, -28));
  EXPECT_EQ(r.sum[2], 100.0);
  EXPECT_EQ(r.sum_sq[0], 2.0 + std::ldexp(1.0, -29));
  EXPECT_EQ(r.sum_sq[2], 1e4 - std::ldexp(1.0, -20));
  EXPECT_EQ(r.events, 7.5);
  EXPECT_EQ(r.density_lookups, 11.0);
  EXPECT_EQ(r.nonfinite_samples, 3u);
}

TEST_F(VulkanAccumulation, NonFiniteSamplesAreCountedAndRecordedAsZero) {
  auto dir = test::temp_dir("gpu-inf");
  test::expect_nonfinite_samples_counted(*backend_, dir);
  std::filesystem::remove_all(dir);
}

TEST_F(VulkanAccumulation, ResumeIsBitIdenticalToAnUninterruptedRender) {
  // 8×8 pixels: 64 spp per pass, so 640 spp are 10 passes.
  test::expect_resume_exact(*backend_, test::chromatic_scattering_scene(8, 8, 640));
}

TEST_F(VulkanAccumulation, ResumeRefusesAnotherBackendsState) {
  Scene s = test::constant_background_scene(4, 4, 8, {1, 1, 1});
  AccumulationState wrong{"cpu", 4, 4, 4, std::vector<uint8_t>(4 * 4 * 6 * sizeof(double) + 24)};
  RenderControl c;
  c.resume = &wrong;
  EXPECT_THROW(backend_->render(s, test::settings_for(s), c), std::invalid_argument);
}

}  // namespace
}  // namespace pyrolume
