#pragma once
// film.aovs on the CPU reference (docs/compositing.md "AOVs"): the light
// layers and features of each sample's channel walks, and the denoiser's
// guide, marched apart from the GPU's shaders/guide.glsl.
#include <glm/glm.hpp>

#include "render/cpu/Walk.h"
#include "scene/Scene.h"

namespace pyrolume::cpu {

// One sample's three channel walks into a pixel's AOV sums
// (RenderResult::aov_sum's layout). L is the sample; recorded is false when
// it was not finite and was recorded as 0: then every layer adds 0.
void add_sample_aovs(const glm::dvec3& L, bool recorded, const WalkAov aov[3], double* sum);

// The pixel (x, y)'s guide into aov_sum at kAovGuide, kAovGuideAlpha: a
// quadrature of the pixel's box filter from five marches (its centre and
// corners), once per render (docs/compositing.md "The guide").
void pixel_guide(const WalkScene& ws, const Camera& camera, int W, int H, int x, int y, Scratch& s, double* aov_sum);

}  // namespace pyrolume::cpu
