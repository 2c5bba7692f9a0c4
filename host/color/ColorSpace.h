#pragma once
// CIE XYZ <-> linear sRGB (IEC 61966-2-1, D65 white) and CIE xy chromaticity.
#include <glm/glm.hpp>

namespace pyrolume::color {

// D65 white point, Y = 1 (CIE 15:2004 xy = 0.3127, 0.3290), the white that the
// sRGB matrix maps to r = g = b = 1.
inline constexpr double kD65WhiteX = 0.95047, kD65WhiteY = 1.0, kD65WhiteZ = 1.08883;
glm::dvec3 d65_white_xyz();

// Linear sRGB from XYZ with the standard matrix derived from the sRGB primaries
// and D65 (IEC 61966-2-1; coefficients as tabulated by B. Lindbloom). Not clamped.
glm::dvec3 xyz_to_linear_srgb(const glm::dvec3& xyz);
glm::dvec3 linear_srgb_to_xyz(const glm::dvec3& rgb);

// Relative luminance of linear sRGB (the Y row of the sRGB -> XYZ matrix).
double srgb_luminance(const glm::dvec3& rgb);

// x = X / (X+Y+Z), y = Y / (X+Y+Z); NaN where X+Y+Z is 0 or not finite.
glm::dvec2 chromaticity_xy(const glm::dvec3& xyz);

// sRGB display encoding (the piecewise 2.4-power transfer function) of one
// linear channel in [0, 1] (clamped).
double srgb_encode(double linear);

}  // namespace pyrolume::color
