#pragma once
// Accumulation (issue 10) on either backend: exact constant radiance at
// 65 536 spp, non-finite samples counted and recorded as 0, bit-identical
// resume, and another backend's state refused. The checks themselves are
// AccumulationChecks.h's; one body per case, instantiated for the CPU
// reference by tests/unit/cpu_accumulation_test.cpp and for Vulkan by
// tests/vulkan/vulkan_accumulation_test.cpp (BackendSuite.h explains).
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/Render.h"
#include "render/cpu/CpuRenderer.h"
#include "shared/gpu_types.h"
#include "support/AccumulationChecks.h"
#include "support/BackendSuite.h"

namespace pyrolume::test {

class AccumulationFixture : public BackendFixture {
 protected:
  using BackendFixture::BackendFixture;
};

using Accumulation = BackendSuite<AccumulationFixture>;

// Double sums (CPU) and Kahan-compensated float sums (GPU) both give the
// constant exactly. On the GPU the values the device holds (float) are the
// exact ones.
TEST_P(Accumulation, ConstantBackgroundIsExactAt65536Spp) {
  const glm::dvec3 bg = per_backend(glm::dvec3(0.3, 0.7123, 1.1), glm::dvec3(double(0.3f), double(0.7123f), double(1.1f)));
  expect_constant_radiance_exact(backend(), constant_background_scene(4, 4, 65536, bg), bg, 1e-6);
}

TEST_P(Accumulation, NonFiniteSamplesAreCountedAndRecordedAsZero) {
  auto dir = temp_dir(backend_name() + "-inf");
  expect_nonfinite_samples_counted(backend(), dir);
  std::filesystem::remove_all(dir);
}

// 64 spp on the CPU; 640 on the GPU, whose 8×8 pixels take 64 spp per pass,
// so that it is 10 passes.
TEST_P(Accumulation, ResumeIsBitIdenticalToAnUninterruptedRender) {
  expect_resume_exact(backend(), chromatic_scattering_scene(8, 8, per_backend(64, 640)));
}

// The other backend's accumulation layout, handed to this one to resume from.
TEST_P(Accumulation, ResumeRefusesAnotherBackendsState) {
  Scene s = constant_background_scene(4, 4, 8, {1, 1, 1});
  AccumulationState wrong =
      cpu() ? AccumulationState{"vulkan", 4, 4, 4, std::vector<uint8_t>(4 * 4 * sizeof(gpu::AccumTexel))}
            : AccumulationState{"cpu", 4, 4, 4, std::vector<uint8_t>(CpuRenderer::accumulation_bytes(4, 4))};
  RenderControl c;
  c.resume = &wrong;
  EXPECT_THROW(backend().render(s, settings_for(s), c), std::invalid_argument);
}

}  // namespace pyrolume::test
