// The GPU accumulation (issue 10), validation layers on. The cases both
// backends share (Kahan-compensated float sums give constant radiance exactly
// at 65 536 spp, mean and Σ L²; non-finite samples counted and recorded as 0;
// a resumed render, state uploaded back to the device, bit-identical to an
// uninterrupted one; another backend's state refused) run from
// tests/support/AccumulationSuite.h (Accumulation.*/"vulkan"); here, the
// readback applying the compensation.
#include <cstring>

#include <gtest/gtest.h>

#include "render/vulkan/RenderSession.h"
#include "shared/gpu_types.h"
#include "support/AccumulationSuite.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Accumulation, "vulkan");
}  // namespace test

namespace {

// (No equilibrium-medium twin of the CPU test: the GPU's emission estimator
// is unbiased there but not constant per sample, so Σ L²/n ≠ Le².)

// The readback is Σ = sum − compensation, evaluated in double: a texel whose
// float sum lost 2^-30 (kept in the compensation) reads back with it.
TEST(VulkanAccumulation, ReadbackAppliesTheKahanCompensation) {
  gpu::AccumTexel t{};
  t.sum = gpu::vec3(1.0f, 3.0f, 100.0f);
  t.events = 7.0f;
  t.sum_c = gpu::vec3(-std::ldexp(1.0f, -30), std::ldexp(1.0f, -28), 0.0f);
  t.events_c = -0.5f;
  t.sum_sq = gpu::vec3(2.0f, 9.0f, 1e4f);
  t.lookups = 11.0f;
  t.sum_sq_c = gpu::vec3(-std::ldexp(1.0f, -29), 0.0f, std::ldexp(1.0f, -20));
  t.nonfinite = 3.0f;
  // The alpha texel follows (docs/compositing.md): Σα 4 less 2^-24, Σα² 3.
  const gpu::AlphaTexel a{4.0f, std::ldexp(1.0f, -24), 3.0f, 0.0f};
  AccumulationState st{"vulkan", 1, 1, 5, std::vector<uint8_t>(sizeof t + sizeof a)};
  std::memcpy(st.data.data(), &t, sizeof t);
  std::memcpy(st.data.data() + sizeof t, &a, sizeof a);
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
  ASSERT_EQ(r.alpha_sum.size(), 1u);
  EXPECT_EQ(r.alpha_sum[0], 4.0 - std::ldexp(1.0, -24));
  EXPECT_EQ(r.alpha_sum_sq[0], 3.0);
}

}  // namespace
}  // namespace pyrolume
