// RenderResult sums → mean and variance of the mean.
#include <gtest/gtest.h>

#include <cmath>

#include "render/RenderImage.h"

using namespace pyrolume;

TEST(RenderImage, MeanAndVarianceOfTheMean) {
  RenderResult r;
  r.width = 1;
  r.height = 1;
  r.spp = 4;
  // Samples R: 1,2,3,4  G: 2,2,2,2  B: 0,0,0,8
  r.sum = {10.0, 8.0, 8.0};
  r.sum_sq = {30.0, 16.0, 64.0};
  Image img = image_from_render(r, true);
  EXPECT_FLOAT_EQ(img.at(0, 0, 0), 2.5f);
  EXPECT_FLOAT_EQ(img.at(0, 0, 1), 2.0f);
  EXPECT_FLOAT_EQ(img.at(0, 0, 2), 2.0f);
  // s² = (Σx² − (Σx)²/n)/(n−1); var of mean = s²/n.
  EXPECT_FLOAT_EQ(img.var_at(0, 0, 0), (30.0f - 25.0f) / 3.0f / 4.0f);  // 5/12
  EXPECT_FLOAT_EQ(img.var_at(0, 0, 1), 0.0f);
  EXPECT_FLOAT_EQ(img.var_at(0, 0, 2), (64.0f - 16.0f) / 3.0f / 4.0f);  // 4

  EXPECT_FALSE(image_from_render(r, false).has_variance());
  r.spp = 1;
  r.sum = {1, 2, 3};
  r.sum_sq = {1, 4, 9};
  Image one = image_from_render(r, true);
  EXPECT_FLOAT_EQ(one.at(0, 0, 2), 3.0f);
  EXPECT_TRUE(std::isinf(one.var_at(0, 0, 0)));  // unknown from a single sample
}
