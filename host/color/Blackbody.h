#pragma once
// Blackbody emission: Planck's law -> CIE XYZ -> linear sRGB (docs/blackbody.md).
#include <optional>

#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace pyrolume::color {

// Linear sRGB radiance of a blackbody at temperature_k in the given mode, for the
// CIE 1931 2° (observer 2) or CIE 1964 10° (observer 10) observer, optionally
// chromatically adapted to a blackbody white at adapt_to_k. Finite and >= 0 for
// every input (T <= 0, NaN, 1e6 ...).
glm::dvec3 blackbody_rgb(double temperature_k, BlackbodyMode mode, int observer = 2,
                         std::optional<double> adapt_to_k = std::nullopt);

}  // namespace pyrolume::color
