#pragma once
// What both backends check before rendering a scene, so that the float
// arithmetic of the GPU (and the float images of both) stays finite by
// construction (docs/robustness.md "Finite by construction"), and no medium
// asks for more tracking steps than any render could take. Each failure is an
// InputError "SCENE: KEY: REASON" naming the key to change (exit 2).
#include <cstddef>

#include "scene/Scene.h"
#include "volume/DenseGrid.h"
#include "volume/StoredVolume.h"

namespace pyrolume {

// Every medium's emission: emission.scale times the brightest colour it can
// take (its rgb or its temperature_k's blackbody colour; a grid's, once it is
// loaded, in check_loaded_medium) must stay within kMaxEmittedRadiance (color/EmissionModel.h);
// σa and σs (times density_scale) within kMaxSigma. Every analytic light's
// value (and a disc sun's radiance) within kMaxEmittedRadiance too.
void check_scene_ranges(const Scene& scene);

// What a grid medium must satisfy once loaded: its majorant optical depth
// (check_majorant_depth), and emission.scale times the brightest blackbody
// colour between 100 K and its hottest voxel's temperature within
// kMaxEmittedRadiance.
void check_loaded_medium(const Scene& scene, size_t medium, const StoredVolume& volume);

// The largest extinction coefficient accepted, per scene unit: far beyond any
// medium (an optical depth of 1e30 per unit), well within float.
inline constexpr double kMaxSigma = 1e30;

// A grid medium's majorant optical depth, σ̄ (the largest σt its texels give,
// per channel) times the diagonal of its world bounds: how many tentative
// collisions a ray through it takes at the medium's global majorant (the CPU
// reference's), and where the GPU's float free flights stop advancing. Past
// kMaxMajorantDepth the medium is refused, naming density_scale.
inline constexpr double kMaxMajorantDepth = 1e8;
void check_majorant_depth(const Scene& scene, size_t medium, const DenseGrid& density);

}  // namespace pyrolume
