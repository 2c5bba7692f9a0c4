// compare metrics on hand-built images whose answers are worked out in comments.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "image/Compare.h"
#include "image/ImageIo.h"
#include "support/TestSupport.h"
#include "util/Error.h"

using namespace pyrolume;
namespace fs = std::filesystem;

namespace {

// 2×1 images. Reference b: pixel 0 = (1,1,1), pixel 1 = (3,3,3).
// a differs by +0.5 in R of pixel 0 and by −1 in B of pixel 1.
Image ref_b() {
  Image b = make_image(2, 1);
  b.rgb = {1, 1, 1, 3, 3, 3};
  return b;
}
Image test_a() {
  Image a = make_image(2, 1);
  a.rgb = {1.5f, 1, 1, 3, 3, 2};
  return a;
}

}  // namespace

TEST(Compare, KnownMetrics) {
  CompareReport r = compare_images(test_a(), ref_b());
  // R: d = (0.5, 0): MSE = 0.125; relMSE = (0.25/(1+0.01) + 0)/2; bias = (4.5−4)/4.
  EXPECT_DOUBLE_EQ(r.channel[0].rmse, std::sqrt(0.125));
  EXPECT_DOUBLE_EQ(r.channel[0].rel_mse, 0.25 / 1.01 / 2.0);  // 0.1237623762
  EXPECT_DOUBLE_EQ(r.channel[0].bias, 0.125);
  // G: identical.
  EXPECT_EQ(r.channel[1].rmse, 0.0);
  EXPECT_EQ(r.channel[1].rel_mse, 0.0);
  EXPECT_EQ(r.channel[1].bias, 0.0);
  // B: d = (0, −1): MSE = 0.5; relMSE = (1/(9+0.01))/2; bias = (3−4)/4.
  EXPECT_DOUBLE_EQ(r.channel[2].rmse, std::sqrt(0.5));
  EXPECT_DOUBLE_EQ(r.channel[2].rel_mse, 1.0 / 9.01 / 2.0);  // 0.0554938957
  EXPECT_DOUBLE_EQ(r.channel[2].bias, -0.25);
  // all: 6 pixel-channels; Σa = 11.5, Σb = 12.
  EXPECT_DOUBLE_EQ(r.all.rmse, std::sqrt(1.25 / 6.0));                   // 0.4564354646
  EXPECT_DOUBLE_EQ(r.all.rel_mse, (0.25 / 1.01 + 1.0 / 9.01) / 6.0);     // 0.0597520906
  EXPECT_DOUBLE_EQ(r.all.bias, -0.5 / 12.0);
  EXPECT_FALSE(r.has_variance);
  EXPECT_EQ(r.outlier_fraction, 0.0);
  EXPECT_EQ(r.all.bias_se, 0.0);
  EXPECT_EQ(r.nonfinite, 0u);

  EXPECT_EQ(format_report(r),
            "size=2x1\n"
            "R rmse=0.353553 rel_mse=0.123762 bias=0.125\n"
            "G rmse=0 rel_mse=0 bias=0\n"
            "B rmse=0.707107 rel_mse=0.0554939 bias=-0.25\n"
            "all rmse=0.456435 rel_mse=0.0597521 bias=-0.0416667\n");
}

TEST(Compare, IdenticalImagesAreZero) {
  CompareReport r = compare_images(ref_b(), ref_b());
  EXPECT_EQ(r.all.rmse, 0.0);
  EXPECT_EQ(r.all.rel_mse, 0.0);
  EXPECT_EQ(r.all.bias, 0.0);
}

TEST(Compare, RelMseEpsilonOnBlackReference) {
  Image a = make_image(1, 1), b = make_image(1, 1);
  a.rgb = {0.1f, 0, 0};
  CompareReport r = compare_images(a, b);
  // R: 0.1² / (0 + 1e-2) = 1 (float 0.1 → use the stored value).
  const double d = double(0.1f);
  EXPECT_DOUBLE_EQ(r.channel[0].rel_mse, d * d / 1e-2);
  EXPECT_TRUE(std::isinf(r.channel[0].bias));  // Σb = 0, Σa > 0
  EXPECT_GT(r.channel[0].bias, 0.0);
  EXPECT_EQ(r.channel[1].bias, 0.0);  // both sums 0
}

TEST(Compare, OutliersAndBiasStandardError) {
  Image a = test_a(), b = ref_b();
  a.variance.assign(6, 0.005f);
  b.variance.assign(6, 0.005f);
  CompareReport r = compare_images(a, b);
  ASSERT_TRUE(r.has_variance);
  // σ = sqrt(0.005 + 0.005) = 0.1 → 4σ = 0.4: |0.5| and |−1| are beyond, the rest not.
  EXPECT_EQ(r.outliers, 2u);
  EXPECT_DOUBLE_EQ(r.outlier_fraction, 2.0 / 6.0);
  // SE_bias = sqrt(Σvar_a + Σvar_b)/|Σb|; R: sqrt(2·0.005·2)/4, all: sqrt(12·0.005)/12.
  EXPECT_NEAR(r.channel[0].bias_se, std::sqrt(0.02) / 4.0, 1e-9);   // 0.0353553
  EXPECT_NEAR(r.all.bias_se, std::sqrt(0.06) / 12.0, 1e-9);         // 0.0204124
  EXPECT_EQ(r.bias_se, r.all.bias_se);
  const std::string text = format_report(r);
  EXPECT_NE(text.find("outliers_4sigma=0.333333 (2 of 6, variance: both)\n"), std::string::npos) << text;
  EXPECT_NE(text.find("R rmse=0.353553 rel_mse=0.123762 bias=0.125 bias_se=0.0353553\n"), std::string::npos) << text;

  // σ = sqrt(0.02 + 0.02) = 0.2 → 4σ = 0.8: only the −1 is beyond.
  a.variance.assign(6, 0.02f);
  b.variance.assign(6, 0.02f);
  EXPECT_EQ(compare_images(a, b).outliers, 1u);
}

TEST(Compare, ZeroVarianceUsesTinyTolerance) {
  Image a = make_image(2, 1, true), b = make_image(2, 1, true);
  b.rgb = {1, 1, 1, 1000, 1000, 1000};
  a.rgb = b.rgb;
  a.rgb[0] += 5e-7f;   // below 1e-6·max(1, 1): not an outlier (float spacing at 1 is 1.2e-7)
  a.rgb[1] += 1e-3f;   // beyond
  a.rgb[3] += 0.0005f; // below 1e-6·1000 = 1e-3 (float spacing at 1000 is 6e-5)
  a.rgb[4] += 0.01f;   // beyond
  CompareReport r = compare_images(a, b);
  EXPECT_EQ(r.outliers, 2u);
}

TEST(Compare, OneSidedVarianceCountsOtherAsExact) {
  Image a = test_a(), b = ref_b();
  a.variance.assign(6, 0.01f);  // σ = 0.1: 0.5 and 1 are beyond
  CompareReport r = compare_images(a, b);
  EXPECT_TRUE(r.has_variance);
  EXPECT_TRUE(r.a_has_variance);
  EXPECT_FALSE(r.b_has_variance);
  EXPECT_EQ(r.outliers, 2u);
  EXPECT_NE(format_report(r).find("variance: a)"), std::string::npos);
}

TEST(Compare, PooledVariance3x3) {
  // 3×3, variance only at the centre (0.09, all channels); R off by 0.45 everywhere.
  Image a = make_image(3, 3, true), b = make_image(3, 3, true);
  for (int c = 0; c < 3; ++c) a.var_at(1, 1, c) = 0.09f;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) a.at(x, y, 0) = 0.45f;
  // Unpooled: centre 4σ = 4·0.3 = 1.2 (inside); the 8 others have var 0 → outliers.
  EXPECT_EQ(compare_images(a, b).outliers, 8u);
  // Pooled, radius 1: centre 0.09/9 → 4σ = 0.4 (outlier); edge 0.09/6 → 4σ = 0.490;
  // corner 0.09/4 → 4σ = 0.6 (both inside). G, B have d = 0.
  CompareReport r = compare_images(a, b, CompareOptions{1});
  EXPECT_EQ(r.outliers, 1u);
  EXPECT_DOUBLE_EQ(r.outlier_fraction, 1.0 / 27.0);
  // bias_se keeps the raw variance: sqrt(0.09·3)/|Σb|, Σb = 0 → inf.
  EXPECT_TRUE(std::isinf(r.all.bias_se));
}

TEST(Compare, NonFiniteCountsAndFails) {
  Image a = test_a(), b = ref_b();
  a.rgb[4] = std::numeric_limits<float>::quiet_NaN();
  a.variance.assign(6, 1.0f);
  CompareReport r = compare_images(a, b);
  EXPECT_EQ(r.nonfinite, 1u);
  EXPECT_EQ(r.outliers, 1u);  // NaN is an outlier; the others are within 4σ = 4
  EXPECT_TRUE(std::isnan(r.all.rel_mse));
  EXPECT_TRUE(std::isnan(r.channel[1].rmse));
  EXPECT_NE(format_report(r).find("nonfinite=1\n"), std::string::npos);
}

TEST(Compare, SizeMismatchNamesBothFiles) {
  Image a = make_image(2, 1), b = make_image(1, 2);
  try {
    compare_images(a, b, {}, "left.exr", "right.exr");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("left.exr"), std::string::npos) << msg;
    EXPECT_NE(msg.find("right.exr"), std::string::npos) << msg;
    EXPECT_NE(msg.find("2x1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("1x2"), std::string::npos) << msg;
  }
}

TEST(CompareCommand, LimitsAndExitStatus) {
  auto dir = test::temp_dir("cmp");
  write_image(dir / "a.exr", test_a(), 0.0);
  write_image(dir / "b.exr", ref_b(), 0.0);
  std::ostringstream out, err;

  // all rel_mse = 0.0597521.
  EXPECT_EQ(run_compare_command(dir / "a.exr", dir / "b.exr", std::nullopt, std::nullopt, out, err), 0);
  EXPECT_EQ(out.str(), format_report(compare_images(test_a(), ref_b())));
  EXPECT_TRUE(err.str().empty());
  EXPECT_EQ(run_compare_command(dir / "a.exr", dir / "b.exr", 0.06, std::nullopt, out, err), 0);
  EXPECT_TRUE(err.str().empty());
  EXPECT_EQ(run_compare_command(dir / "a.exr", dir / "b.exr", 0.059, std::nullopt, out, err), 3);
  EXPECT_NE(err.str().find("exceeds --max-relmse"), std::string::npos) << err.str();

  // --max-outliers without variance is bad input.
  try {
    run_compare_command(dir / "a.exr", dir / "b.exr", std::nullopt, 0.1, out, err);
    ADD_FAILURE() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--variance"), std::string::npos) << e.what();
  }

  // With variance σ = 0.1: 2 of 6 beyond 4σ.
  Image av = test_a(), bv = ref_b();
  av.variance.assign(6, 0.005f);
  bv.variance.assign(6, 0.005f);
  write_image(dir / "av.exr", av, 0.0);
  write_image(dir / "bv.exr", bv, 0.0);
  std::ostringstream out2, err2;
  EXPECT_EQ(run_compare_command(dir / "av.exr", dir / "bv.exr", std::nullopt, 0.34, out2, err2), 0);
  EXPECT_EQ(run_compare_command(dir / "av.exr", dir / "bv.exr", std::nullopt, 0.33, out2, err2), 3);
  EXPECT_NE(err2.str().find("exceeds --max-outliers"), std::string::npos) << err2.str();
  EXPECT_NE(out2.str().find("outliers_4sigma=0.333333"), std::string::npos) << out2.str();

  // NaN fails a rel_mse gate.
  Image an = test_a();
  an.rgb[0] = std::numeric_limits<float>::quiet_NaN();
  write_image(dir / "nan.exr", an, 0.0);
  EXPECT_EQ(run_compare_command(dir / "nan.exr", dir / "b.exr", 1e9, std::nullopt, out, err), 3);

  // Missing file and negative limits are input errors.
  EXPECT_THROW(run_compare_command(dir / "gone.exr", dir / "b.exr", std::nullopt, std::nullopt, out, err), InputError);
  EXPECT_THROW(run_compare_command(dir / "a.exr", dir / "b.exr", -1.0, std::nullopt, out, err), InputError);
  fs::remove_all(dir);
}
