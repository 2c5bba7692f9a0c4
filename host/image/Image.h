#pragma once
// A linear-radiance RGB image as the host sees it: what a render produces, what
// EXR/PNG files hold, what `compare` measures.
#include <cstddef>
#include <vector>

namespace pyrolume {

struct Image {
  int width = 0, height = 0;
  // Interleaved RGB, width*height*3 floats, row 0 = top, linear radiance.
  std::vector<float> rgb;
  // Empty, or interleaved RGB variance of the per-pixel MEAN (sample variance / spp),
  // same layout as rgb. Written to EXR as variance.R, variance.G, variance.B.
  std::vector<float> variance;
  // Samples per pixel behind the means, and the number the render was asked
  // for (less when it was interrupted). EXR attributes "spp" and "spp_target";
  // 0 = unknown (not a render, or a format without metadata).
  int spp = 0, spp_target = 0;
  // Empty, or width*height alpha values (EXR channel A, premultiplied: RGB
  // already holds coverage; docs/compositing.md "Alpha").
  std::vector<float> alpha;
  // PNG carries alpha too (film.transparent), as straight alpha.
  bool transparent = false;

  size_t pixel_count() const { return size_t(width) * size_t(height); }
  size_t index(int x, int y, int c) const { return (size_t(y) * size_t(width) + size_t(x)) * 3 + size_t(c); }
  float& at(int x, int y, int c) { return rgb[index(x, y, c)]; }
  float at(int x, int y, int c) const { return rgb[index(x, y, c)]; }
  float& var_at(int x, int y, int c) { return variance[index(x, y, c)]; }
  float var_at(int x, int y, int c) const { return variance[index(x, y, c)]; }
  bool has_variance() const { return !variance.empty(); }
  bool has_alpha() const { return !alpha.empty(); }
};

// A black width×height image; with_variance also allocates zeroed variance.
inline Image make_image(int width, int height, bool with_variance = false) {
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.assign(img.pixel_count() * 3, 0.0f);
  if (with_variance) img.variance.assign(img.pixel_count() * 3, 0.0f);
  return img;
}

}  // namespace pyrolume
