#pragma once
// The hard-case suite's fixture (issue 10, item 1; docs/robustness.md "Hard
// cases"): every case is a typed test that runs once on the CPU reference and
// once on the Vulkan backend (VulkanFixture: validation on, any message
// fails). Every render goes through HardCase::render, which asserts what all
// hard cases share: the samples asked for were taken, no sample was
// non-finite (stats nonfinite_samples == 0), every pixel sum is finite, and
// (CPU) no tentative collision exceeded the majorant. Scenes and closed forms
// come from tests/support; grids are written by the tests into a temporary
// folder that the fixture removes.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "render/Backend.h"
#include "render/cpu/CpuRenderer.h"
#include "support/AnalyticScenes.h"
#include "support/Stats.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "support/VulkanFixture.h"

namespace pyrolume::hard {

// The CPU reference as a suite-wide backend, like VulkanFixture's.
class CpuBackend : public ::testing::Test {
 protected:
  static constexpr bool kVulkan = false;
  static void SetUpTestSuite() { backend_ = std::make_unique<CpuRenderer>(); }
  static void TearDownTestSuite() { backend_.reset(); }
  static inline std::unique_ptr<CpuRenderer> backend_;
};

class VulkanBackend : public test::VulkanFixture {
 protected:
  static constexpr bool kVulkan = true;
};

using Backends = ::testing::Types<CpuBackend, VulkanBackend>;

// Test names end in /cpu or /vulkan (ctest -R selects a backend).
struct BackendNames {
  template <class T>
  static std::string GetName(int) {
    return std::is_same_v<T, VulkanBackend> ? "vulkan" : "cpu";
  }
};

inline const EmissionEstimator kEstimators[] = {EmissionEstimator::Absorption, EmissionEstimator::Collision};

// Absorption-estimator samples are Bernoulli-like: pool the variance over 3×3
// (Stats.h explains).
using test::pixel_mean;
using test::pooled;

// The rectangle [x0, x0 + w) × [y0, y0 + h) of a render, as a render of its own
// (for closed forms that hold on part of the image only).
inline RenderResult crop(const RenderResult& r, int x0, int y0, int w, int h) {
  RenderResult c = test::zero_render(w, h, r.spp);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k) {
        const size_t from = ((size_t(y0 + y) * r.width) + (x0 + x)) * 3 + k, to = (size_t(y) * w + x) * 3 + k;
        c.sum[to] = r.sum[from];
        c.sum_sq[to] = r.sum_sq[from];
      }
  return c;
}

// The constant box of cpu_vdb_test / vulkan_vdb_test (test::ConstantBoxSetup:
// lat, box, c, constant_box_scene, field) is at hand; `dir` is removed at the end.
// Pixel-channels whose samples were all identical (SE = 0) cannot be
// z-tested, and where the medium is very thin (a grid's far edge ramp, a
// density of 1e-6) the event that would make a sample differ may simply not
// have happened in n samples. Such a pixel-channel (common value v) is
// consistent with an expected mean μ as long as seeing no event was not
// improbable: a sample that differs from v differs by at most `range`, so an
// event has probability q >= |μ − v|/range per sample and
// P(no event in n) <= exp(−n·|μ − v|/range). Where that bound is >= 1e-4
// (n·|μ − v|/range <= 9.2) the expectation is moved to v; everywhere else the
// closed form is unchanged (and SE = 0 pixels must match it to 1e-6).
inline std::function<glm::dvec3(int, int)> allow_unseen_rare_events(const RenderResult& r,
                                                                    std::function<glm::dvec3(int, int)> exact,
                                                                    glm::dvec3 range) {
  return [&r, exact, range](int x, int y) {
    glm::dvec3 e = exact(x, y);
    for (int k = 0; k < 3; ++k) {
      const size_t i = (size_t(y) * r.width + x) * 3 + k;
      const double v = r.sum[i] / r.spp;
      // "Every sample the same" up to float accumulation (the GPU's Σx² − n·v²
      // rounds to ~1e-7 relative, not to 0).
      if (test::sample_variance(r.sum[i], r.sum_sq[i], r.spp) > 1e-9 * (1.0 + v * v)) continue;
      if (r.spp * std::abs(e[k] - v) <= 9.2 * range[k]) e[k] = v;
    }
    return e;
  };
}

template <class B>
class HardCase : public B, protected test::ConstantBoxSetup {
 protected:
  static constexpr bool kVulkan = B::kVulkan;

  HardCase() : test::ConstantBoxSetup(kVulkan ? "hardcases-vulkan" : "hardcases-cpu") {}
  ~HardCase() override {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }

  // Renders on this suite's backend with the scene's film settings and checks
  // what every hard case must satisfy.
  RenderResult render(const Scene& s, const char* what = "") {
    RenderResult r = this->backend_->render(s, test::settings_for(s), {});
    check(r, s.film.spp, what);
    if constexpr (!kVulkan) EXPECT_EQ(this->backend_->majorant_violations(), 0u) << what << ": sigma_t above the majorant";
    return r;
  }

  static void check(const RenderResult& r, int spp, const char* what) {
    EXPECT_EQ(r.spp, spp) << what;
    EXPECT_EQ(r.nonfinite_samples, 0u) << what << ": non-finite samples";
    size_t bad = 0;
    for (size_t i = 0; i < r.sum.size(); ++i) bad += !std::isfinite(r.sum[i]) || !std::isfinite(r.sum_sq[i]);
    EXPECT_EQ(bad, 0u) << what << ": non-finite pixel sums";
  }

  // The CPU reference image of the same scene (another seed, `spp` samples),
  // for Vulkan cases with no closed form.
  static RenderResult cpu_reference(Scene s, int spp, uint32_t seed) {
    s.film.spp = spp;
    s.film.seed = seed;
    CpuRenderer cpu;
    RenderResult r = cpu.render(s, test::settings_for(s), {});
    check(r, spp, "cpu reference");
    EXPECT_EQ(cpu.majorant_violations(), 0u);
    return r;
  }

  // Both emission estimators against a closed form; returns the last render.
  // rare_range > 0: allow_unseen_rare_events with that range.
  RenderResult expect_closed_form(Scene s, const std::function<glm::dvec3(int, int)>& exact, const char* what,
                                  const test::ZTestOptions& o = pooled(), glm::dvec3 rare_range = glm::dvec3(0.0)) {
    RenderResult r;
    for (const EmissionEstimator est : kEstimators) {
      s.integrator.emission_estimator = est;
      r = render(s, what);
      const bool rare = rare_range.x > 0.0 || rare_range.y > 0.0 || rare_range.z > 0.0;
      const test::ZTestReport rep =
          test::ztest_against_exact(r, rare ? allow_unseen_rare_events(r, exact, rare_range) : exact, o);
      EXPECT_TRUE(rep.ok) << what << " [" << to_string(est) << "] " << rep.summary();
      std::printf("%s [%s, %s]: %s; %.2f s\n", what, to_string(est), kVulkan ? "vulkan" : "cpu", rep.summary().c_str(),
                  r.seconds);
    }
    return r;
  }

  // The check can fail: the same render against a deliberately wrong closed
  // form is rejected.
  static void expect_rejected(const RenderResult& r, const std::function<glm::dvec3(int, int)>& wrong,
                              const char* what, const test::ZTestOptions& o = pooled()) {
    const test::ZTestReport rep = test::ztest_against_exact(r, wrong, o);
    EXPECT_FALSE(rep.ok) << "deliberately wrong (" << what << ") was accepted: " << rep.summary();
  }

  // Every pixel of every sample equals `value` (up to float accumulation).
  static void expect_every_pixel(const RenderResult& r, const glm::dvec3& value, const char* what) {
    size_t off = 0;
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int k = 0; k < 3; ++k) {
          const size_t i = (size_t(y) * r.width + x) * 3 + k;
          const bool mean_ok = std::abs(m[k] - value[k]) <= 1e-6 * std::abs(value[k]);
          // Σx² = n·v² when every sample is v.
          const bool sq_ok = std::abs(r.sum_sq[i] - r.spp * value[k] * value[k]) <= 1e-5 * r.spp * value[k] * value[k];
          if (!(mean_ok && sq_ok) && off++ < 5)
            ADD_FAILURE() << what << ": pixel (" << x << ", " << y << ") channel " << k << " mean " << m[k]
                          << " sum_sq " << r.sum_sq[i] << ", expected every sample = " << value[k];
        }
      }
    EXPECT_EQ(off, 0u) << what << ": pixel-channels differing from " << value.x << " " << value.y << " " << value.z;
  }
};

}  // namespace pyrolume::hard
