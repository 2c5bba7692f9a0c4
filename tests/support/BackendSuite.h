#pragma once
// One test body on both backends (docs/testing.md, "One body, both
// backends"). A suite's bodies live in a shared header
// (tests/support/<Topic>Suite.h) as `TEST_P(Topic, Name)` on a fixture
// derived from BackendSuite; tests/unit/cpu_<topic>_test.cpp instantiates it
// for "cpu" (ctest label `unit`, so tools/sanitize runs the CPU cases) and
// tests/vulkan/vulkan_<topic>_test.cpp for "vulkan" (label `vulkan`):
//
//   INSTANTIATE_BACKEND_SUITE(Topic, "cpu");
//
// ctest names end in the backend: Topic.Name/"cpu", Topic.Name/"vulkan".
// Per-backend differences (tolerances that follow from double vs float
// accumulation, spp, checks only one backend can make) are written in the
// body with per_backend(cpu_value, vulkan_value) or an `if (cpu())`, so they
// stay visible and per backend.
//
// Every render goes through render(), which asserts what all renders share:
// the samples asked for were taken, no sample was non-finite, every pixel sum
// is finite, and (CPU) no tentative collision exceeded the majorant. On
// Vulkan, validation layers are on and TearDown fails a test after which
// validation reported anything (as VulkanFixture does).
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "backends/Backends.h"
#include "render/cpu/CpuRenderer.h"
#include "render/vulkan/VulkanRenderer.h"
#include "support/AnalyticScenes.h"

namespace pyrolume::test {

// Sets a Vulkan backend's test switches (render/vulkan/VulkanHooks.h) for
// its lifetime, and puts the defaults back after.
class HooksSet {
 public:
  HooksSet(Backend& vulkan, const VulkanHooks& hooks) : vulkan_(dynamic_cast<VulkanRenderer&>(vulkan)) {
    vulkan_.set_hooks(hooks);
  }
  ~HooksSet() { vulkan_.set_hooks({}); }
  HooksSet(const HooksSet&) = delete;
  HooksSet& operator=(const HooksSet&) = delete;

 private:
  VulkanRenderer& vulkan_;
};

// A fixture for one named backend ("cpu" or "vulkan"); suite-wide renderers,
// made on first use and released at the end of the suite.
class BackendFixture : public ::testing::Test {
 protected:
  explicit BackendFixture(std::string backend) : backend_name_(std::move(backend)) {}

  static void TearDownTestSuite() {
    cpu_.reset();
    vulkan_.reset();
  }
  void TearDown() override {
    if (vulkan() && vulkan_)
      EXPECT_EQ(vulkan_->validation_messages(), 0u) << "Vulkan validation reported problems";
  }

  const std::string& backend_name() const { return backend_name_; }
  bool cpu() const { return backend_name_ == "cpu"; }
  bool vulkan() const { return backend_name_ == "vulkan"; }
  // A value that differs by backend, named at the place it is used.
  template <class T>
  T per_backend(T on_cpu, T on_vulkan) const {
    return cpu() ? on_cpu : on_vulkan;
  }

  // The renderers themselves, for what render() does not cover.
  Backend& vulkan_backend() {
    EXPECT_TRUE(vulkan()) << "vulkan_backend() in a " << backend_name_ << " test";
    if (!vulkan_) {
      BackendOptions o;
      o.validation = true;
      vulkan_ = make_backend("vulkan", o);
    }
    return *vulkan_;
  }
  // This fixture's backend, as the interface both implement.
  Backend& backend() { return cpu() ? static_cast<Backend&>(cpu_renderer()) : vulkan_backend(); }
  CpuRenderer& cpu_renderer() {
    if (!cpu_) cpu_ = std::make_unique<CpuRenderer>();
    return *cpu_;
  }

  RenderResult render(const Scene& s) { return render(s, settings_for(s)); }
  // A Vulkan render with the test switches of render/vulkan/VulkanHooks.h,
  // which are back at their defaults afterwards.
  RenderResult render_with(const Scene& s, const VulkanHooks& hooks) {
    const HooksSet set(vulkan_backend(), hooks);
    return render(s);
  }
  RenderResult render(const Scene& s, const RenderSettings& rs) {
    RenderResult r;
    if (cpu()) {
      CpuRenderer& c = cpu_renderer();
      r = c.render(s, rs, {});
      EXPECT_EQ(c.majorant_violations(), 0u) << "sigma_t exceeded the majorant";
    } else {
      r = vulkan_backend().render(s, rs, {});
    }
    EXPECT_EQ(r.spp, rs.spp);
    EXPECT_EQ(r.nonfinite_samples, 0u) << "non-finite samples";
    for (double v : r.sum) EXPECT_TRUE(std::isfinite(v)) << "non-finite pixel sum";
    return r;
  }

 private:
  std::string backend_name_;
  static inline std::unique_ptr<CpuRenderer> cpu_;
  static inline std::unique_ptr<Backend> vulkan_;
};

// The parametrised form: the backend is the test parameter.
template <class Fixture>
class BackendSuite : public Fixture, public ::testing::WithParamInterface<std::string> {
 protected:
  BackendSuite() : Fixture(this->GetParam()) {}
};

}  // namespace pyrolume::test

// Instantiates a suite of TEST_P bodies for one backend ("cpu" or "vulkan").
// gtest numbers the one value (Suite.Name/0); ctest's test discovery names it
// by its value, Suite.Name/"cpu", as it does Backends/Sequence.Name/"cpu".
#define INSTANTIATE_BACKEND_SUITE(Suite, backend) \
  INSTANTIATE_TEST_SUITE_P(, Suite, ::testing::Values(std::string(backend)))
