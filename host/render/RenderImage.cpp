#include "render/RenderImage.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace pyrolume {

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
