#pragma once
// The emission rule both renderers follow (docs/blackbody.md): which
// temperatures emit, where the blackbody range ends, how emission.scale and
// the temperature become Le, and the most radiance an emitter may give. The
// CPU reference evaluates Planck directly (temperature_Le); the GPU reads a
// BlackbodyLut over [kEmissionMinK, kEmissionMaxK] (color/BlackbodyLut.h).
// The GPU's copies of the radiance limits (shaders/shared/gpu_types.h) are
// asserted equal in render/vulkan/GpuScene.cpp.
#include <algorithm>
#include <optional>

#include <glm/glm.hpp>

#include "color/Blackbody.h"
#include "color/BlackbodyMode.h"

namespace pyrolume {

// The blackbody range: nothing emits below kEmissionMinK (the scene's default
// temperature.cutoff_k too), and hotter temperatures are clamped to kEmissionMaxK.
inline constexpr double kEmissionMinK = 100.0;
inline constexpr double kEmissionMaxK = 1.0e6;

// The most radiance any emitter (a medium's emission, an environment texel
// times its scale) may give: beyond it the renderers' float sums could
// overflow (docs/robustness.md "Finite by construction"); refused at load.
inline constexpr float kMaxEmittedRadiance = 1e12f;

// Whether temperature T (kelvin) emits: above the medium's cutoff_k and at
// least kEmissionMinK. False for NaN.
inline bool temperature_emits(double T, double cutoff_k) { return T > cutoff_k && T >= kEmissionMinK; }

// Le at temperature T: emission.scale times the blackbody colour at
// min(T, kEmissionMaxK) (Planck at 5 nm, color::blackbody_rgb_5nm, as the LUT
// is built); 0 where T does not emit.
inline glm::dvec3 temperature_Le(double T, double cutoff_k, double scale, BlackbodyMode mode, int observer,
                                 std::optional<double> adapt_to_k) {
  if (!temperature_emits(T, cutoff_k)) return glm::dvec3(0.0);
  return scale * color::blackbody_rgb_5nm(std::min(T, kEmissionMaxK), mode, observer, adapt_to_k);
}

}  // namespace pyrolume
