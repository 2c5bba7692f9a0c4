#include "color/ColorSpace.h"
#include "util/Math.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pyrolume::color {
namespace {

// Rows of M (XYZ -> linear sRGB) and its inverse, for the D65 white above.
constexpr double kXyzToSrgb[3][3] = {
    {3.2404542, -1.5371385, -0.4985314},
    {-0.9692660, 1.8760108, 0.0415560},
    {0.0556434, -0.2040259, 1.0572252},
};
constexpr double kSrgbToXyz[3][3] = {
    {0.4124564, 0.3575761, 0.1804375},
    {0.2126729, 0.7151522, 0.0721750},
    {0.0193339, 0.1191920, 0.9503041},
};

}  // namespace

glm::dvec3 d65_white_xyz() { return {kD65WhiteX, kD65WhiteY, kD65WhiteZ}; }

glm::dvec3 xyz_to_linear_srgb(const glm::dvec3& xyz) { return mul(kXyzToSrgb, xyz); }

glm::dvec3 linear_srgb_to_xyz(const glm::dvec3& rgb) { return mul(kSrgbToXyz, rgb); }

double srgb_luminance(const glm::dvec3& rgb) {
  return kSrgbToXyz[1][0] * rgb.r + kSrgbToXyz[1][1] * rgb.g + kSrgbToXyz[1][2] * rgb.b;
}

glm::dvec2 chromaticity_xy(const glm::dvec3& xyz) {
  const double sum = xyz.x + xyz.y + xyz.z;
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
  }
  return {xyz.x / sum, xyz.y / sum};
}

double srgb_encode(double linear) {
  const double v = std::clamp(std::isnan(linear) ? 0.0 : linear, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

}  // namespace pyrolume::color
