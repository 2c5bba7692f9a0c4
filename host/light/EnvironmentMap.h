#pragma once
// An environment light: a lat-long (equirectangular) radiance map around the
// scene, importance-sampled by a 2D piecewise-constant distribution
// (docs/lights.md). Radiance is linear RGB.
//
// Convention (Blender's equirectangular world texture, Cycles
// direction_to_equirectangular): +Z is up. A map direction
//   d = (sinθ cosφ, sinθ sinφ, cosθ),  θ = π·v,  φ = π − 2π·u
// i.e. v = 0 is the top row (+Z), v = 1 the bottom row (−Z); u = 0.5 (the
// image's centre column) looks along +X, u = 0.25 along +Y, u = 0 / 1 along −X,
// u = 0.75 along −Y: u grows CLOCKWISE seen from above (from +Z looking down).
// `rotation_deg` turns the environment right-handedly about +Z: what the
// unrotated map shows at direction d appears at Rz(rotation_deg)·d, so
// radiance(d) = scale · map(Rz(−rotation_deg)·d).
//
// Texel (i, j) (column i, row j, row 0 = top) covers u ∈ [i/W, (i+1)/W),
// v ∈ [j/H, (j+1)/H); its value sits at the texel centre. Lookups are bilinear
// between texel centres, wrapping around in u and clamping in v.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "image/Image.h"

namespace pyrolume {

// A direction sampled from a light: Tungsten-style plain record.
struct EnvSample {
  glm::dvec3 dir{0.0};       // unit, world space, pointing away from the scene
  double pdf = 0.0;          // solid-angle measure (1/sr); 0: no sample
  glm::dvec3 radiance{0.0};  // radiance(dir), scale included
};

class EnvironmentMap {
 public:
  EnvironmentMap() = default;

  // Reads a lat-long map (EXR; Radiance .hdr and 8-bit images via read_image).
  // Missing file, unreadable or not an image → InputError "FILE: REASON".
  // zenith_y: the scene is Y up (scene up_axis "y"); the map's zenith, +Z in
  // its own frame, is then world +Y: world d is looked up at (d.x, −d.z, d.y)
  // (a quarter turn about +X), before the rotation about the zenith.
  static EnvironmentMap load(const std::filesystem::path& file, double scale = 1.0, double rotation_deg = 0.0,
                             bool zenith_y = false);
  // From an image already in memory (tests, generated skies). Negative and
  // non-finite texel values are set to 0 (counted in sanitized_texels()).
  // Throws std::invalid_argument for an empty image or a non-finite / negative scale.
  static EnvironmentMap from_image(const Image& img, double scale = 1.0, double rotation_deg = 0.0, bool zenith_y = false,
                                   const std::string& name = "environment");

  int width() const { return width_; }
  int height() const { return height_; }
  double scale() const { return scale_; }
  double rotation_deg() const { return rotation_deg_; }
  const std::string& name() const { return name_; }
  size_t sanitized_texels() const { return sanitized_; }

  // False when nothing can be sampled: an all-black map or scale 0. sample()
  // then returns pdf 0 and pdf() is 0; next-event estimation must skip the light.
  bool has_distribution() const { return total_weight_ > 0.0; }
  // ≈ ∫ Y(radiance(ω)) dω over the sphere (Y: sRGB luminance, scale included),
  // for choosing between lights by power.
  double power() const { return power_; }

  // Map coordinates (u, v) ∈ [0,1)² of a world direction and back (rotation
  // included; the direction need not be normalised).
  glm::dvec2 direction_to_uv(const glm::dvec3& dir) const;
  glm::dvec3 uv_to_direction(const glm::dvec2& uv) const;

  // Bilinear radiance seen along world direction dir, × scale.
  glm::dvec3 radiance(const glm::dvec3& dir) const;
  // Bilinear texel value at map coordinates (no scale).
  glm::dvec3 lookup_uv(const glm::dvec2& uv) const;

  // Importance sampling (u2 ∈ [0,1)²): row by the marginal CDF, column by the
  // row's conditional CDF, each continuous inside its texel (pbrt-v4
  // PiecewiseConstant2D). The (u, v) density is piecewise constant,
  //   p_uv(u, v) = W·H·w_ij / Σw,
  // and the solid-angle pdf is p_uv / (2π² sinθ) (dω = 2π² sinθ du dv).
  EnvSample sample(const glm::dvec2& u2) const;
  // The same solid-angle pdf for any direction: pdf(s.dir) == s.pdf.
  double pdf(const glm::dvec3& dir) const;
  // p_uv of texel (i, j): the piecewise-constant (u, v) density.
  double pdf_uv_texel(int i, int j) const { return double(pdf_uv_[size_t(j) * width_ + i]); }
  double pdf_uv(const glm::dvec2& uv) const;

  // The sampling CDFs: (H + 1) marginal CDF values over rows, then for each
  // row j its (W + 1) conditional CDF values at offset (H + 1) + j·(W + 1).
  // Each starts at 0 and ends at exactly 1 (a row of weight 0 holds a uniform
  // CDF; it is never chosen). The GPU layout is render/vulkan/LightPacking.h.
  const std::vector<float>& cdf() const { return cdf_; }
  // Texel (i, j) as stored (no scale), and the rotation about the zenith.
  glm::dvec3 texel(int i, int j) const {
    const size_t k = (size_t(j) * width_ + i) * 3;
    return {rgb_[k], rgb_[k + 1], rgb_[k + 2]};
  }
  double cos_rotation() const { return cos_rot_; }
  double sin_rotation() const { return sin_rot_; }
  bool zenith_y() const { return zenith_y_; }

 private:
  void build_distribution();

  std::string name_;
  int width_ = 0, height_ = 0;
  double scale_ = 1.0, rotation_deg_ = 0.0;
  double cos_rot_ = 1.0, sin_rot_ = 0.0;
  bool zenith_y_ = false;
  std::vector<float> rgb_;      // W·H·3, row 0 = top
  std::vector<float> pdf_uv_;   // W·H
  std::vector<float> cdf_;      // see cdf()
  double total_weight_ = 0.0;
  double power_ = 0.0;
  size_t sanitized_ = 0;
};

}  // namespace pyrolume
