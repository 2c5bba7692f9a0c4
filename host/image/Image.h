#pragma once
// A linear-radiance RGB image as the host sees it: what a render produces, what
// EXR/PNG files hold, what `compare` measures.
#include <cstddef>
#include <vector>

namespace pyrolume {

// Arbitrary output variables: the beauty split into light layers, and first-hit
// features. All empty, or all sized like Image::rgb (depth: one per pixel).
struct Aovs {
  // Light layers, interleaved RGB: they sum to Image::rgb per sample.
  //   emission:   light emitted by media that reaches the camera unscattered;
  //   scatter:    light whose path's first vertex is a scattering in a medium;
  //   surface:    light whose path's first vertex is on a surface;
  //   background: the background, environment map, sun discs and sphere
  //               lights as the camera ray sees them (through the media).
  std::vector<float> emission, scatter, surface, background;
  // Features of the camera ray's first event (a surface, or a real collision
  // in a medium), averaged over the pixel's samples that have one:
  //   albedo: a surface's albedo; a medium's single-scattering albedo σs/σt;
  //   normal: a surface's normal, facing the camera (XYZ, world space); 0 in media;
  //   depth:  the distance from the camera to the event; 0 where no sample has one.
  std::vector<float> albedo, normal;
  std::vector<float> depth;  // one per pixel
  // The denoiser's guide, averaged over the pixel's samples (empty in files
  // written before it existed): what each camera ray sees unscattered (the
  // media's emission, then the background or a sphere light through them),
  // by a deterministic ray march (the expected `emission` + `background`
  // layers, without their noise), and the expected alpha of that ray
  // (guide_alpha, one per pixel). docs/compositing.md "The guide".
  std::vector<float> guide, guide_alpha;
  bool has_guide() const { return !guide.empty(); }

  bool empty() const { return emission.empty(); }
};

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
  // Empty, or the render's AOVs (film.aovs; docs/compositing.md "AOVs").
  Aovs aovs;

  size_t pixel_count() const { return size_t(width) * size_t(height); }
  size_t index(int x, int y, int c) const { return (size_t(y) * size_t(width) + size_t(x)) * 3 + size_t(c); }
  float& at(int x, int y, int c) { return rgb[index(x, y, c)]; }
  float at(int x, int y, int c) const { return rgb[index(x, y, c)]; }
  float& var_at(int x, int y, int c) { return variance[index(x, y, c)]; }
  float var_at(int x, int y, int c) const { return variance[index(x, y, c)]; }
  bool has_variance() const { return !variance.empty(); }
  bool has_alpha() const { return !alpha.empty(); }
  bool has_aovs() const { return !aovs.empty(); }
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
