#pragma once
// RenderResult (per-pixel sums) → Image (per-pixel mean, optional variance of the mean).
#include "image/Image.h"
#include "render/Render.h"

namespace pyrolume {

// mean = Σx / n, with n = result.spp.
// with_variance: variance of the mean = s²/n, s² = (Σx² − (Σx)²/n)/(n − 1) (unbiased
// sample variance), clamped at 0 against cancellation; +inf when n < 2 (unknown).
// n = 0 gives a black image. Alpha: Σα / n per pixel, when the result has it.
// AOVs (result.aov_sum, when the render had them) go into Image::aovs.
Image image_from_render(const RenderResult& result, bool with_variance);

// The light layers as means over all samples (Σ/n), the features as means over
// the samples that have a first event (0 where none has).
Aovs aovs_from_render(const RenderResult& result);

}  // namespace pyrolume
