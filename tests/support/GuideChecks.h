#pragma once
// Comparing two renders' denoiser guides (film.aovs; docs/compositing.md
// "The guide"), which are deterministic: value for value.
#include <cstddef>

#include <gtest/gtest.h>

#include "render/RenderImage.h"

namespace pyrolume::test {

// Expects a and b to hold the same guide (RGB and alpha) bit for bit, and a's
// guide to be more than 0 somewhere (a guide of zeros would match anything
// that marched nothing).
inline void expect_same_guide(const Image& a, const Image& b) {
  ASSERT_TRUE(a.aovs.has_guide());
  ASSERT_TRUE(b.aovs.has_guide());
  ASSERT_EQ(a.aovs.guide.size(), b.aovs.guide.size());
  ASSERT_EQ(a.aovs.guide_alpha.size(), b.aovs.guide_alpha.size());
  size_t differing = 0;
  double total = 0.0;
  for (size_t k = 0; k < a.aovs.guide.size(); ++k) {
    differing += a.aovs.guide[k] != b.aovs.guide[k];
    total += a.aovs.guide[k];
  }
  for (size_t i = 0; i < a.aovs.guide_alpha.size(); ++i) differing += a.aovs.guide_alpha[i] != b.aovs.guide_alpha[i];
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(total, 0.0);
}

}  // namespace pyrolume::test
