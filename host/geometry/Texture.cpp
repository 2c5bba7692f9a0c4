#include "geometry/Texture.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <glm/gtc/packing.hpp>
#include <stdexcept>

#include "image/ImageIo.h"
#include "util/Error.h"

namespace pyrolume::geometry {
namespace {

int wrap(int i, int n) {
  const int m = i % n;
  return m < 0 ? m + n : m;
}

// EXR starts with the magic number 20000630; Radiance files with "#?".
bool is_linear_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(head), 4);
  if (head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01) return true;
  return head[0] == '#' && head[1] == '?';
}

}  // namespace

Texture::Texture(int width, int height, std::vector<float> rgb, bool srgb_source)
    : width_(width), height_(height), rgb_(std::move(rgb)), srgb_source_(srgb_source) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("texture: empty image");
  if (rgb_.size() != size_t(width) * size_t(height) * 3) throw std::invalid_argument("texture: size mismatch");
}

Texture Texture::load(const std::filesystem::path& file) {
  Image img = read_image(file);  // InputError "FILE: REASON" on failure
  if (img.width <= 0 || img.height <= 0) throw input_error(file.string(), "", "empty image");
  // A NaN or infinite albedo makes every path that meets it non-finite. Test
  // hook (no scene key): PYROLUME_TEST_NONFINITE_TEXTURES=1 lets them through,
  // the one way tests have to make samples non-finite on purpose and check
  // that the accumulation records them as 0 and counts them.
  if (std::getenv("PYROLUME_TEST_NONFINITE_TEXTURES") == nullptr) {
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < img.rgb.size(); ++i)
      if (!std::isfinite(img.rgb[i]) && bad++ == 0) first = i / 3;
    if (bad > 0)
      throw input_error(file.string(), "",
                        std::to_string(bad) + " texel values are NaN or infinite (the first at x " +
                            std::to_string(first % size_t(img.width)) + ", y " + std::to_string(first / size_t(img.width)) +
                            "); an albedo texture must be finite");
  }
  const bool srgb = !is_linear_file(file);
  Texture t(img.width, img.height, std::move(img.rgb), srgb);
  t.file_ = file;
  return t;
}

glm::dvec3 Texture::texel(int x, int y) const {
  const size_t i = (size_t(wrap(y, height_)) * size_t(width_) + size_t(wrap(x, width_))) * 3;
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

glm::dvec3 Texture::lookup(const glm::dvec2& uv) const {
  // Continuous texel coordinates with centres at integer + 0.5; v flipped
  // because row 0 is the top of the image.
  const double x = uv.x * width_ - 0.5;
  const double y = (1.0 - uv.y) * height_ - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double wx = x - fx, wy = y - fy;
  // Wrap the integer part first so huge uvs keep their fraction.
  const int ix = int(std::fmod(fx, double(width_))), iy = int(std::fmod(fy, double(height_)));
  return (1 - wy) * ((1 - wx) * texel(ix, iy) + wx * texel(ix + 1, iy)) +
         wy * ((1 - wx) * texel(ix, iy + 1) + wx * texel(ix + 1, iy + 1));
}

std::vector<uint8_t> Texture::rgba8_srgb() const {
  std::vector<uint8_t> out(size_t(width_) * size_t(height_) * 4);
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) {
    for (int c = 0; c < 3; ++c) out[i * 4 + size_t(c)] = srgb_encode_u8(rgb_[i * 3 + size_t(c)]);
    out[i * 4 + 3] = 255;
  }
  return out;
}

std::vector<uint16_t> Texture::rgba16f() const {
  std::vector<uint16_t> out(size_t(width_) * size_t(height_) * 4);
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) {
    for (int c = 0; c < 3; ++c) out[i * 4 + size_t(c)] = glm::packHalf1x16(rgb_[i * 3 + size_t(c)]);
    out[i * 4 + 3] = glm::packHalf1x16(1.0f);
  }
  return out;
}

std::vector<float> Texture::rgba32f() const {
  std::vector<float> out(size_t(width_) * size_t(height_) * 4);
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) {
    for (int c = 0; c < 3; ++c) out[i * 4 + size_t(c)] = rgb_[i * 3 + size_t(c)];
    out[i * 4 + 3] = 1.0f;
  }
  return out;
}

}  // namespace pyrolume::geometry
