#pragma once
// How a temperature becomes a colour and a brightness (docs/blackbody.md);
// color/Blackbody.h evaluates it, the scene model (scene/Scene.h) names it.
namespace pyrolume {

// Seed: "chromaticity" in scene files (colour only); StefanBoltzmann: the
// default, brightness ∝ T⁴ (docs/blackbody.md).
enum class BlackbodyMode { Seed, Peak, Physical, StefanBoltzmann };

}  // namespace pyrolume
