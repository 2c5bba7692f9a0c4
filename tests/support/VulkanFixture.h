#pragma once
// A gtest fixture base for suites that render on the Vulkan backend: one
// backend (instance, device) per suite, validation layers on, and every test
// ends by checking that validation reported nothing.
#include <memory>

#include <gtest/gtest.h>

#include "render/Backend.h"

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

  static inline std::unique_ptr<Backend> backend_;
};

}  // namespace pyrolume::test
