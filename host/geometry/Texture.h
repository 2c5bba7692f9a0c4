#pragma once
// Albedo textures: linear RGB texels, bilinear lookup with wrap (repeat)
// addressing, and the packings the GPU upload needs.
//
// UV convention (OBJ, Blender): uv (0, 0) is the image's BOTTOM-left, (1, 1) its
// top-right. Images store row 0 at the top, so a lookup reads image row
// y = (1 − v)·height. Texel (x, y) has its centre at
// uv = ((x + 0.5)/width, 1 − (y + 0.5)/height).
//
// On the GPU: upload the rows as stored (row 0 first) into a 2D image with
// linear filtering and REPEAT addressing, and sample texture(tex, vec2(u, 1 − v)).
// 8-bit sources go up as VK_FORMAT_R8G8B8A8_SRGB (rgba8_srgb(): the sampler
// decodes sRGB before filtering, as lookup() does); EXR/HDR sources as
// VK_FORMAT_R16G16B16A16_SFLOAT (rgba16f()) or R32G32B32A32_SFLOAT (rgba32f()).
// Ignore mipmaps: one level, textureLod(…, 0).
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace pyrolume::geometry {

class Texture {
 public:
  Texture() = default;
  // rgb: width·height·3 linear floats, row 0 = top. Throws std::invalid_argument
  // on a size mismatch or an empty image.
  Texture(int width, int height, std::vector<float> rgb, bool srgb_source = false);

  // PNG/JPG/…: 8/16-bit sRGB, decoded to linear; EXR and .hdr: linear (via
  // image/ImageIo.h). Missing or unreadable file, or a NaN/Inf texel →
  // InputError naming it (docs/robustness.md "Finite by construction").
  static Texture load(const std::filesystem::path& file);
  // The file it was loaded from (empty when built in memory), for messages.
  const std::filesystem::path& file() const { return file_; }

  int width() const { return width_; }
  int height() const { return height_; }
  // True when the file was sRGB-encoded (PNG & co): upload it as RGBA8_SRGB.
  bool srgb_source() const { return srgb_source_; }
  const std::vector<float>& rgb() const { return rgb_; }

  // Linear RGB of texel (x, y), row y = 0 at the top; x and y wrap.
  glm::dvec3 texel(int x, int y) const;
  // Bilinear, wrap addressing, v flipped (see above).
  glm::dvec3 lookup(const glm::dvec2& uv) const;

  // Packed rows (row 0 first), alpha 1: sRGB-encoded bytes (round-trips an
  // 8-bit source exactly), half floats, floats.
  std::vector<uint8_t> rgba8_srgb() const;
  std::vector<uint16_t> rgba16f() const;
  std::vector<float> rgba32f() const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> rgb_;
  bool srgb_source_ = false;
  std::filesystem::path file_;
};

}  // namespace pyrolume::geometry
