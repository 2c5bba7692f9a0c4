#include "render/RenderImage.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace pyrolume {

Aovs aovs_from_render(const RenderResult& result) {
  const size_t pixels = size_t(result.width) * size_t(result.height);
  if (result.aov_sum.size() != pixels * kAovValues)
    throw std::logic_error("aovs_from_render: AOV sums do not match width*height*kAovValues");
  Aovs a;
  for (auto* v : {&a.emission, &a.scatter, &a.surface, &a.background, &a.albedo, &a.normal}) v->assign(pixels * 3, 0.0f);
  a.depth.assign(pixels, 0.0f);
  a.guide.assign(pixels * 3, 0.0f);
  a.guide_alpha.assign(pixels, 0.0f);
  const double n = double(result.spp);
  for (size_t i = 0; i < pixels; ++i) {
    const double* s = result.aov_sum.data() + i * kAovValues;
    const double hits = s[kAovHits];
    for (int c = 0; c < 3; ++c) {
      if (n > 0.0) {  // the layers are means over all samples, like the beauty
        a.emission[i * 3 + c] = float(s[kAovEmission + c] / n);
        a.scatter[i * 3 + c] = float(s[kAovScatter + c] / n);
        a.surface[i * 3 + c] = float(s[kAovSurface + c] / n);
        a.background[i * 3 + c] = float(s[kAovBackground + c] / n);
        a.guide[i * 3 + c] = float(s[kAovGuide + c]);  // the pixel's, not a sum
      }
      if (hits > 0.0) {  // the features, over the samples that have a first event
        a.albedo[i * 3 + c] = float(s[kAovAlbedo + c] / hits);
        a.normal[i * 3 + c] = float(s[kAovNormal + c] / hits);
      }
    }
    if (hits > 0.0) a.depth[i] = float(s[kAovDepth] / hits);
    if (n > 0.0) a.guide_alpha[i] = float(s[kAovGuideAlpha]);
  }
  return a;
}

Image image_from_render(const RenderResult& result, bool with_variance) {
  Image img = make_image(result.width, result.height, with_variance);
  img.spp = result.spp;
  img.spp_target = result.spp_target;
  const size_t count = img.rgb.size();
  if (result.sum.size() != count || (with_variance && result.sum_sq.size() != count))
    throw std::logic_error("image_from_render: sums do not match width*height*3");
  const double n = double(result.spp);
  if (!result.alpha_sum.empty()) {
    if (result.alpha_sum.size() != img.pixel_count())
      throw std::logic_error("image_from_render: alpha sums do not match width*height");
    img.alpha.assign(img.pixel_count(), 0.0f);
    if (n > 0.0)
      for (size_t i = 0; i < img.alpha.size(); ++i) img.alpha[i] = float(result.alpha_sum[i] / n);
  }
  if (!result.aov_sum.empty()) img.aovs = aovs_from_render(result);
  if (n <= 0.0) return img;
  for (size_t i = 0; i < count; ++i) {
    const double mean = result.sum[i] / n;
    img.rgb[i] = float(mean);
    if (!with_variance) continue;
    if (n < 2.0) {
      img.variance[i] = std::numeric_limits<float>::infinity();
      continue;
    }
    const double s2 = std::max(0.0, (result.sum_sq[i] - result.sum[i] * mean) / (n - 1.0));
    img.variance[i] = float(s2 / n);
  }
  return img;
}

}  // namespace pyrolume
