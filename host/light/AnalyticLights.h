#pragma once
// The scene's `lights` array as both backends read it (docs/lights.md
// "Analytic lights"): their values, the disc sun's radiance, and the power
// by which light selection weighs them.
#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace pyrolume {

// scale × rgb, or scale × the blackbody colour (chromaticity) at temperature_k
// normalised to luminance 1: irradiance (distant), intensity (point, spot) or
// radiance (sphere), linear sRGB.
glm::dvec3 light_value(const Light& l);

// A distant light's disc: its angular radius θ = angle_deg/2 (radians), and
// 1 − cos θ computed without cancellation (2 sin²(θ/2)); 0 for a delta light.
double disc_half_angle(const Light& l);
double disc_one_minus_cos(const Light& l);
// The radiance of a disc of angular radius θ whose irradiance on a plane
// facing it is E: E = ∫ L cos ω dω over the cone = π L sin²θ.
glm::dvec3 disc_radiance(const Light& l);

// A spot light's soft edge: cos of the cone's half-angle (dark beyond) and of
// where the falloff starts (full intensity inside), and the factor
// smoothstep(cos_end, cos_start, cos θ) (pbrt-v4's SpotLight); a hard edge
// when they are equal.
struct SpotCone {
  double cos_end = 0.0, cos_start = 1.0;
};
SpotCone spot_cone(const Light& l);
double spot_falloff(const SpotCone& c, double cos_theta);

// Light selection's weight, luminance-weighted (docs/lights.md "Choosing a
// light"): point 4πI, spot 2πI(1 − (cos_start + cos_end)/2), sphere
// π·L·4πr² (watts, comparable with an emissive medium's 4π∫σa Le dV); a
// distant light its irradiance E (comparable with an environment's ∫L dω:
// both are power per unit area of the scene's cross-section).
double light_power(const Light& l);

}  // namespace pyrolume
