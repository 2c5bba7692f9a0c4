#pragma once
// Von Kries chromatic adaptation in Bradford cone-response space (Lam 1985, as
// given by Fairchild 1998, "Color Appearance Models"). Nguyen et al. 2002
// ("Physically based modeling and animation of fire", SIGGRAPH) adapt fire to the
// white of a blackbody so that the hottest flame reads as white, not blue.
#include <glm/glm.hpp>

namespace pyrolume::color {

// Maps xyz seen under source_white_xyz to the colour that looks the same under
// dest_white_xyz: XYZ' = M_B⁻¹ · diag(rho_d / rho_s) · M_B · XYZ. The whites may
// have any Y; the map sends source_white_xyz to dest_white_xyz × (Y_s / Y_d), so
// luminance of the white is kept. Throws std::invalid_argument if a cone
// response of either white is not positive and finite.
glm::dvec3 von_kries_bradford(const glm::dvec3& xyz, const glm::dvec3& source_white_xyz,
                              const glm::dvec3& dest_white_xyz);

}  // namespace pyrolume::color
