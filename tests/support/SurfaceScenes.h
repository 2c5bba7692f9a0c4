#pragma once
// Scenes with surfaces and environment maps for the renderer tests
// (header-only): shape builders, files written by the tests (an asymmetric
// sRGB PNG, an open-box OBJ, lat-long EXRs) and independent implementations of
// the documented texture convention (docs/surfaces.md: IEC 61966-2-1 decode,
// bilinear in linear RGB, wrap, uv (0, 0) = the image's bottom-left) so the
// expected images do not come from the code under test.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "image/Image.h"
#include "image/ImageIo.h"
#include "scene/Scene.h"
#include "support/AnalyticScenes.h"
#include "support/TestSupport.h"

namespace pyrolume::test {

inline Shape sphere_shape(glm::dvec3 center, double radius, glm::dvec3 albedo) {
  Shape s;
  s.type = Shape::Type::Sphere;
  s.center = center;
  s.radius = radius;
  s.albedo = albedo;
  return s;
}

// size 0: unbounded along that axis.
inline Shape plane_shape(glm::dvec3 center, glm::dvec3 normal, glm::dvec2 size, glm::dvec3 albedo) {
  Shape s;
  s.type = Shape::Type::Plane;
  s.center = center;
  s.normal = normal;
  s.size = size;
  s.albedo = albedo;
  return s;
}

inline Shape mesh_shape(const std::filesystem::path& obj, glm::dvec3 albedo) {
  Shape s;
  s.type = Shape::Type::Mesh;
  s.mesh = obj;
  s.albedo = albedo;
  return s;
}

// IEC 61966-2-1 decode, written here independently of image/ImageIo.
inline double srgb_to_linear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

// ---------------------------------------------------------------- texture ----

// A 4×4 sRGB texture, asymmetric top/bottom (green: top bright, bottom dark)
// and left/right (red grows to the right), with a blue checker.
struct TexelBytes {
  int w = 4, h = 4;
  std::vector<uint8_t> rgb;  // row 0 = top
  TexelBytes() {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        rgb.push_back(uint8_t(30 + 60 * x));             // r: left → right
        rgb.push_back(uint8_t(230 - 65 * y));            // g: top bright, bottom dark
        rgb.push_back(uint8_t((x + y) % 2 ? 200 : 40));  // b: checker
      }
  }
};

// Writes the bytes as an 8-bit PNG: the linear values given to write_image
// encode back to exactly these bytes.
inline std::filesystem::path write_texel_png(const TexelBytes& bytes, const std::filesystem::path& dir,
                                             const std::string& name = "albedo.png") {
  Image img = make_image(bytes.w, bytes.h);
  for (size_t k = 0; k < bytes.rgb.size(); ++k) img.rgb[k] = float(srgb_to_linear(bytes.rgb[k] / 255.0));
  const auto png = dir / name;
  write_image(png, img);
  return png;
}

enum class TexVariant { Correct, NoFlip, NoDecode };

// Bilinear, wrapping lookup at uv in linear RGB; `sig` changes across texel
// cells (for the pixel quadrature's refinement).
inline glm::dvec3 texture_lookup(const TexelBytes& t, glm::dvec2 uv, TexVariant v, int* sig) {
  auto texel = [&](int x, int y) {
    x = ((x % t.w) + t.w) % t.w;
    y = ((y % t.h) + t.h) % t.h;
    glm::dvec3 c;
    for (int k = 0; k < 3; ++k) {
      const double e = t.rgb[(size_t(y) * t.w + x) * 3 + k] / 255.0;
      c[k] = v == TexVariant::NoDecode ? e : srgb_to_linear(e);
    }
    return c;
  };
  const double X = uv.x * t.w - 0.5;
  const double Y = (v == TexVariant::NoFlip ? uv.y : 1.0 - uv.y) * t.h - 0.5;
  const double x0 = std::floor(X), y0 = std::floor(Y), fx = X - x0, fy = Y - y0;
  if (sig) *sig = int(x0) * 1000 + int(y0);
  const int i = int(x0), j = int(y0);
  return (1 - fy) * ((1 - fx) * texel(i, j) + fx * texel(i + 1, j)) +
         fy * ((1 - fx) * texel(i, j + 1) + fx * texel(i + 1, j + 1));
}

// ------------------------------------------------------------------- mesh ----

// Cube [-1, 1]³ without its +y face (counter-clockwise quads, triangulated by
// the loader): a concave mesh that inter-reflects.
inline std::filesystem::path write_open_box_obj(const std::filesystem::path& dir) {
  std::string obj =
      "v -1 -1 -1\nv 1 -1 -1\nv 1 -1 1\nv -1 -1 1\nv -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\n"
      "f 1 2 3 4\n"   // bottom
      "f 1 5 6 2\n"   // z = -1
      "f 2 6 7 3\n"   // x = +1
      "f 3 7 8 4\n"   // z = +1
      "f 4 8 5 1\n";  // x = -1
  std::filesystem::path p = dir / "open_box.obj";
  write_file(p, obj);
  return p;
}

// ------------------------------------------------------------ environment ----

// An 8 × 4 lat-long map with a different value in every texel and channel.
inline Image env_pattern_image() {
  Image img = make_image(8, 4);
  img.rgb.clear();
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      img.rgb.push_back(0.1f + 0.3f * x);                      // r grows with u
      img.rgb.push_back(2.0f - 0.5f * y);                      // g: bright at the top
      img.rgb.push_back((x + 2 * y) % 3 == 0 ? 1.5f : 0.25f);  // b: a pattern
    }
  return img;
}

inline Image uniform_image(int w, int h, glm::vec3 value) {
  Image img = make_image(w, h);
  for (size_t p = 0; p < img.pixel_count(); ++p)
    for (int c = 0; c < 3; ++c) img.rgb[p * 3 + c] = value[c];
  return img;
}

// --------------------------------------------------------------- helpers ----

// Precomputed pixel averages of L(fx, fy, sig) over a W × H film, as the lookup
// ztest_against_exact wants.
inline std::function<glm::dvec3(int, int)> exact_image(
    int W, int H, const std::function<glm::dvec3(double fx, double fy, int* sig)>& L, int base = 8) {
  auto vals = std::make_shared<std::vector<glm::dvec3>>(size_t(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) (*vals)[size_t(y) * W + x] = pixel_average(L, x, y, base);
  return [vals, W](int x, int y) { return (*vals)[size_t(y) * W + x]; };
}

}  // namespace pyrolume::test
