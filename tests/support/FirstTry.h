#pragma once
// The first-try check of issue 22 (docs/sources.md): a scene that names only a
// VDB file renders to a PNG that shows a fire. Measured on the PNG's bytes:
//  - visible: the fraction of pixels whose luminance (Rec. 709 weights on the
//    encoded values / 255) exceeds 0.1;
//  - not clipped flat: of those, the fraction with a channel at 255;
//  - coloured by temperature: the mean G/R of the brightest tenth of them
//    against the dimmest tenth's (hotter blackbodies are whiter).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include <stb_image.h>

namespace pyrolume::test {

struct FirstTryLook {
  int width = 0, height = 0;
  double visible = 0.0;             // fraction of all pixels
  double clipped = 0.0;             // fraction of the visible pixels
  double hot_g_over_r = 0.0, cool_g_over_r = 0.0;
  std::string summary() const {
    char s[200];
    std::snprintf(s, sizeof s, "%dx%d: %.1f %% visible, %.1f %% of them clipped, G/R %.3f (hottest tenth) vs %.3f",
                  width, height, 100 * visible, 100 * clipped, hot_g_over_r, cool_g_over_r);
    return s;
  }
  bool looks_like_fire() const { return visible >= 0.03 && clipped <= 0.10 && hot_g_over_r > cool_g_over_r; }
};

inline FirstTryLook first_try_look(const std::filesystem::path& png) {
  FirstTryLook look;
  int n = 0;
  unsigned char* px = stbi_load(png.string().c_str(), &look.width, &look.height, &n, 3);
  if (!px) return look;
  struct Lit {
    double luminance, g_over_r;
  };
  std::vector<Lit> lit;
  size_t clipped = 0;
  const size_t pixels = size_t(look.width) * size_t(look.height);
  for (size_t i = 0; i < pixels; ++i) {
    const unsigned char* p = px + 3 * i;
    const double y = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
    if (!(y > 0.1)) continue;
    lit.push_back({y, double(p[1]) / std::max(1, int(p[0]))});
    clipped += p[0] == 255 || p[1] == 255 || p[2] == 255;
  }
  stbi_image_free(px);
  if (lit.empty()) return look;
  look.visible = double(lit.size()) / double(pixels);
  look.clipped = double(clipped) / double(lit.size());
  std::sort(lit.begin(), lit.end(), [](const Lit& a, const Lit& b) { return a.luminance < b.luminance; });
  const size_t tenth = std::max<size_t>(1, lit.size() / 10);
  auto mean_gr = [&](size_t from) {
    double s = 0.0;
    for (size_t i = from; i < from + tenth; ++i) s += lit[i].g_over_r;
    return s / double(tenth);
  };
  look.cool_g_over_r = mean_gr(0);
  look.hot_g_over_r = mean_gr(lit.size() - tenth);
  return look;
}

}  // namespace pyrolume::test
