// BlackbodyLut: the GPU's 1D texture reproduces direct evaluation within 0.1 %
// (per channel, relative to the largest channel) over 500–40 000 K, and the
// documented range behaviour holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "color/Blackbody.h"
#include "color/BlackbodyLut.h"
#include "color/ColorSpace.h"

using namespace pyrolume;
using namespace pyrolume::color;

namespace {

// Worst |lut_c − direct_c| / max(direct_r, direct_g, direct_b) over n log-spaced
// temperatures in [lo, hi].
double worst_error(const BlackbodyLut& lut, double lo, double hi, int n, double* at_k) {
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double T = lo * std::pow(hi / lo, (k + 0.5) / n);
    const glm::dvec3 ref = blackbody_rgb(T, lut.mode(), lut.observer(), lut.adapt_to_k());
    const glm::dvec3 got = lut.lookup(T);
    const double scale = std::max({ref.r, ref.g, ref.b});
    for (int c = 0; c < 3; ++c) {
      const double e = scale > 0 ? std::abs(got[c] - ref[c]) / scale : std::abs(got[c]);
      if (e > worst) worst = e, *at_k = T;
    }
  }
  return worst;
}

}  // namespace

TEST(BlackbodyLut, LinearFilteringWithinBoundOver500To40000K) {
  struct Config { BlackbodyMode mode; int observer; std::optional<double> adapt; };
  const Config configs[] = {{BlackbodyMode::Seed, 2, {}},      {BlackbodyMode::Peak, 2, {}},
                            {BlackbodyMode::Physical, 2, {}},  {BlackbodyMode::Seed, 10, {}},
                            {BlackbodyMode::Physical, 10, {}}, {BlackbodyMode::Peak, 2, 3000.0}};
  for (const Config& c : configs) {
    const BlackbodyLut lut(c.mode, c.observer, c.adapt);
    double at = 0;
    const double worst = worst_error(lut, 500.0, 40000.0, 20000, &at);
    EXPECT_LE(worst, 1e-3) << to_string(c.mode) << ", observer " << c.observer << ": worst at " << at << " K";
  }
}

TEST(BlackbodyLut, BoundTestCanFail) {
  // A LUT 8x coarser breaks the bound at the steep Wien end: the test above sees it.
  const BlackbodyLut coarse(BlackbodyMode::Physical, 2, std::nullopt, 1024);
  double at = 0;
  EXPECT_GT(worst_error(coarse, 500.0, 40000.0, 2000, &at), 1e-3);
}

TEST(BlackbodyLut, TexelsHoldDirectValuesAndLuminance) {
  const BlackbodyLut lut(BlackbodyMode::Peak, 2, std::nullopt, 512, 400.0, 50000.0);
  ASSERT_EQ(lut.rgba().size(), 512u * 4);
  EXPECT_DOUBLE_EQ(lut.temperature_at(0), 400.0);
  EXPECT_DOUBLE_EQ(lut.temperature_at(511), 50000.0);
  for (uint32_t i : {0u, 100u, 300u, 511u}) {
    const double T = lut.temperature_at(i);
    const glm::dvec3 ref = blackbody_rgb(T, BlackbodyMode::Peak);
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(lut.rgba()[4 * i + c], float(ref[c])) << i;
    EXPECT_FLOAT_EQ(lut.rgba()[4 * i + 3], float(srgb_luminance(ref)));
    // At a texel's own temperature the filter returns that texel.
    EXPECT_LT(std::abs(lut.lookup(T).g - ref.g), 1e-5 * std::max(ref.g, 1e-30) + 1e-30) << i;
  }
}

TEST(BlackbodyLut, ParamsMapTexelTemperaturesToTexelCentres) {
  const BlackbodyLut lut(BlackbodyMode::Seed);
  const BlackbodyLutParams& p = lut.params();
  EXPECT_EQ(p.size, BlackbodyLut::kDefaultSize);
  EXPECT_EQ(p.t_min_k, 100.0f);
  EXPECT_EQ(p.t_max_k, 1e6f);
  // What the shader computes, in float: s = ln(T)·scale + bias = (i + 0.5)/N.
  for (uint32_t i : {0u, 1u, 1000u, 4095u, p.size - 1}) {
    const float s = std::log(float(lut.temperature_at(i))) * p.log_scale + p.log_bias;
    EXPECT_NEAR(s * p.size, i + 0.5, 2e-3) << "texel " << i << " (float coordinate error, in texels)";
  }
}

TEST(BlackbodyLut, RangeBehaviour) {
  const BlackbodyLut lut(BlackbodyMode::Physical);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  // Below t_min (and NaN, T <= 0): no emission.
  for (double T : {99.999, 50.0, 0.0, -5.0, nan, -inf}) EXPECT_EQ(lut.lookup(T), glm::dvec3(0.0)) << T;
  // Above t_max: the value at t_max, exactly what clamp-to-edge gives.
  const glm::dvec3 top = lut.lookup(1e6);
  EXPECT_EQ(lut.lookup(2e6), top);
  EXPECT_EQ(lut.lookup(inf), top);
  const glm::dvec3 direct = blackbody_rgb(1e6, BlackbodyMode::Physical);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(top[c] - direct[c]) / direct[c], 1e-6);
  // Every texel finite and non-negative, in float.
  for (float v : lut.rgba()) EXPECT_TRUE(std::isfinite(v) && v >= 0.0f);
  EXPECT_THROW(BlackbodyLut(BlackbodyMode::Seed, 2, std::nullopt, 1), std::invalid_argument);
  EXPECT_THROW(BlackbodyLut(BlackbodyMode::Seed, 2, std::nullopt, 64, 1000.0, 500.0), std::invalid_argument);
  EXPECT_THROW(BlackbodyLut(BlackbodyMode::Seed, 7), std::invalid_argument);
}

TEST(BlackbodyLut, BakedOnceEqualsAFreshBake) {
  // The per-process copy (BlackbodyLut::baked) holds what a fresh bake of the
  // same mode, observer and adaptation holds, and tells them apart.
  const BlackbodyLut fresh(BlackbodyMode::Peak, 10, 3000.0);
  const BlackbodyLut first = BlackbodyLut::baked(BlackbodyMode::Peak, 10, 3000.0);
  const BlackbodyLut again = BlackbodyLut::baked(BlackbodyMode::Peak, 10, 3000.0);
  EXPECT_EQ(first.rgba(), fresh.rgba());
  EXPECT_EQ(again.rgba(), fresh.rgba());
  EXPECT_EQ(again.params().log_scale, fresh.params().log_scale);
  const BlackbodyLut other = BlackbodyLut::baked(BlackbodyMode::Peak, 10, 4000.0);
  EXPECT_EQ(other.adapt_to_k(), std::optional<double>(4000.0));
  EXPECT_NE(other.rgba(), fresh.rgba());
  EXPECT_EQ(BlackbodyLut::baked(BlackbodyMode::Physical).rgba(), BlackbodyLut(BlackbodyMode::Physical).rgba());
  EXPECT_THROW(BlackbodyLut::baked(BlackbodyMode::Peak, 7), std::invalid_argument);
}
