#pragma once
// A gtest fixture base for suites that render on the Vulkan backend: one
// backend (instance, device) per suite, validation layers on, and every test
// ends by checking that validation reported nothing.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "backends/Backends.h"
#include "support/AnalyticScenes.h"

namespace pyrolume::test {

class VulkanFixture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    BackendOptions o;
    o.validation = true;
    backend_ = make_backend("vulkan", o);
  }
  static void TearDownTestSuite() { backend_.reset(); }
  void TearDown() override {
    if (backend_) EXPECT_EQ(backend_->validation_messages(), 0u) << "Vulkan validation reported problems";
  }

  // A render of the scene as written, which must finish every sample with
  // finite values.
  static RenderResult render(const Scene& s) {
    RenderResult r = backend_->render(s, settings_for(s), {});
    EXPECT_EQ(r.spp, s.film.spp);
    EXPECT_EQ(r.nonfinite_samples, 0u) << "non-finite samples";
    for (double v : r.sum) EXPECT_TRUE(std::isfinite(v)) << "non-finite pixel sum";
    return r;
  }

  static inline std::unique_ptr<Backend> backend_;
};

}  // namespace pyrolume::test
