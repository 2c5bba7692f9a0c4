#pragma once
// The smoke check of issue 46 (docs/sources.md "Smoke is smoke"): a scene that
// names only a smoke export renders smoke that is
//  - visible: the fraction of pixels with alpha (EXR A = 1 − T) above 0.05;
//  - shaded: among those, the 90th percentile of display luminance (Rec. 709
//    weights on the PNG's bytes / 255, exposure 0, the default view) over the 10th;
//  - not glowing: the image mean equals that of the same scene with
//    emission.scale 0 within 4 standard errors (each from --variance),
//    rendered with the same seed (common random numbers: where nothing
//    emits the two renders are the same computation; any glow shows as a
//    difference far beyond the independent-sample SE used here);
//  - not clipped: the fraction of all pixels with a channel at 255.
// run_smoke_look renders the shortest scene and its emission.scale-0 twin
// through the CLI.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "image/DisplayTransform.h"
#include "image/ImageIo.h"
#include "support/TestSupport.h"

namespace pyrolume::test {

struct SmokeLook {
  int width = 0, height = 0;
  double visible = 0.0;         // fraction of all pixels with A > 0.05
  double p10 = 0.0, p90 = 0.0;  // display luminance percentiles within the smoke
  double clipped = 0.0;         // fraction of all pixels with a channel at 255
  double mean = 0.0, mean_se = 0.0;     // linear RGB mean and its standard error
  double mean0 = 0.0, mean0_se = 0.0;   // the same with emission.scale 0
  // Measurement mode only (PYROLUME_SMOKE_LOOK): the twin with another seed,
  // an independent estimate (NaN when not rendered).
  double mean0_seed2 = NAN, mean0_seed2_se = NAN;
  double glow_z_independent() const {
    return (mean - mean0_seed2) / std::sqrt(mean_se * mean_se + mean0_seed2_se * mean0_seed2_se);
  }
  double shading() const { return p10 > 0.0 ? p90 / p10 : (p90 > 0.0 ? INFINITY : 0.0); }
  double glow_z() const {
    const double se = std::sqrt(mean_se * mean_se + mean0_se * mean0_se);
    return se > 0.0 ? (mean - mean0) / se : (mean == mean0 ? 0.0 : INFINITY);
  }
  bool visible_ok() const { return visible >= 0.05; }
  bool shaded_ok() const { return shading() >= 2.0; }
  bool no_glow() const { return std::abs(glow_z()) <= 4.0; }
  bool clip_ok() const { return clipped <= 0.01; }
  bool looks_like_smoke() const { return visible_ok() && shaded_ok() && no_glow() && clip_ok(); }
  std::string summary() const {
    char s[300];
    std::snprintf(s, sizeof s,
                  "%dx%d: %.1f %% visible (A > 0.05), p90/p10 %.2f (%.3f/%.3f), glow %+.2f SE (mean %.5g vs %.5g "
                  "with emission.scale 0), %.2f %% clipped",
                  width, height, 100 * visible, shading(), p90, p10, glow_z(), mean, mean0, 100 * clipped);
    return s;
  }
};

// The linear mean over every pixel and channel and its standard error, from
// the EXR's per-pixel variance of the mean.
inline void image_mean(const Image& img, double& mean, double& se) {
  double sum = 0.0, var = 0.0;
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    sum += img.rgb[i];
    if (img.has_variance()) var += img.variance[i];
  }
  const double n = double(img.rgb.size());
  mean = n > 0 ? sum / n : 0.0;
  se = n > 0 ? std::sqrt(var) / n : 0.0;
}

// Measures a render read from EXR (with A and variance), its display bytes
// as the PNG a render writes at the defaults (exposure 0, the default view).
inline SmokeLook smoke_look(const Image& img) {
  SmokeLook look;
  if (img.alpha.size() != img.pixel_count() || img.pixel_count() == 0) return look;
  const std::vector<unsigned char> bytes = display_rgb8(img, 0.0, kDefaultView);
  const unsigned char* px = bytes.data();
  look.width = img.width;
  look.height = img.height;
  std::vector<double> lum;
  size_t clipped = 0;
  for (size_t i = 0; i < img.pixel_count(); ++i) {
    const unsigned char* p = px + 3 * i;
    clipped += p[0] == 255 || p[1] == 255 || p[2] == 255;
    if (img.alpha[i] > 0.05f) lum.push_back((0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0);
  }
  const double pixels = double(img.pixel_count());
  look.visible = double(lum.size()) / pixels;
  look.clipped = double(clipped) / pixels;
  if (!lum.empty()) {
    std::sort(lum.begin(), lum.end());
    auto rank = [&](double q) { return lum[std::min(lum.size() - 1, size_t(q * double(lum.size() - 1) + 0.5))]; };
    look.p10 = rank(0.10);
    look.p90 = rank(0.90);
  }
  image_mean(img, look.mean, look.mean_se);
  return look;
}

// The film the check renders at: tiny by default (tests must be cheap);
// PYROLUME_SMOKE_LOOK="W H SPP BACKEND" measures at another size, e.g.
// "320 240 32 vulkan" for issue 46's numbers (docs/sources.md).
struct SmokeLookFilm {
  int width = 48, height = 48, spp = 8;
  std::string backend = "cpu";
  static SmokeLookFilm from_env() {
    SmokeLookFilm f;
    if (const char* e = std::getenv("PYROLUME_SMOKE_LOOK")) {
      char b[32] = {0};
      if (std::sscanf(e, "%d %d %d %31s", &f.width, &f.height, &f.spp, b) == 4) f.backend = b;
    }
    return f;
  }
  std::string flags(int seed) const {
    return " --backend " + backend + " --width " + std::to_string(width) + " --height " + std::to_string(height) +
           " --spp " + std::to_string(spp) + " --seed " + std::to_string(seed);
  }
};

// Renders {"media": [{"type": "vdb", "file": VDB}]} from `dir` to EXR, and
// the same with "emission": {"scale": 0}; `err` gets the first render's
// stderr. `name`.exr stays in `dir`.
inline SmokeLook run_smoke_look(const std::filesystem::path& dir, const std::filesystem::path& vdb,
                                const std::string& name, std::string* err = nullptr,
                                const SmokeLookFilm& film = SmokeLookFilm::from_env()) {
  auto q = [](const std::filesystem::path& p) { return "'" + p.string() + "'"; };
  write_file(dir / (name + ".json"), R"({"media": [{"type": "vdb", "file": ")" + vdb.string() + R"("}]})");
  write_file(dir / (name + "_dark.json"),
             R"({"media": [{"type": "vdb", "file": ")" + vdb.string() + R"(", "emission": {"scale": 0}}]})");
  const std::string scene = q(dir / (name + ".json")), dark = q(dir / (name + "_dark.json"));
  CliResult r = run_cli("render " + scene + " -o " + q(dir / (name + ".exr")) + " --variance" + film.flags(1));
  EXPECT_EQ(r.status, 0) << r.err;
  if (err) *err = r.err;
  r = run_cli("render " + dark + " -o " + q(dir / (name + "_dark.exr")) + " --variance" + film.flags(1));
  EXPECT_EQ(r.status, 0) << r.err;
  // PYROLUME_SMOKE_GALLERY=DIR: the render also as DIR/NAME.png (docs/gallery's smoke images).
  if (const char* g = std::getenv("PYROLUME_SMOKE_GALLERY")) {
    r = run_cli("render " + scene + " -o " + q(std::filesystem::path(g) / (name + ".png")) + film.flags(1));
    EXPECT_EQ(r.status, 0) << r.err;
  }
  SmokeLook look = smoke_look(read_image(dir / (name + ".exr")));
  const Image d = read_image(dir / (name + "_dark.exr"));
  image_mean(d, look.mean0, look.mean0_se);
  if (std::getenv("PYROLUME_SMOKE_LOOK")) {
    r = run_cli("render " + dark + " -o " + q(dir / (name + "_dark2.exr")) + " --variance" + film.flags(2));
    EXPECT_EQ(r.status, 0) << r.err;
    image_mean(read_image(dir / (name + "_dark2.exr")), look.mean0_seed2, look.mean0_seed2_se);
    std::printf("%s: independent seeds: glow %+.2f SE (mean %.5g vs %.5g)\n", name.c_str(), look.glow_z_independent(),
                look.mean, look.mean0_seed2);
  }
  return look;
}

}  // namespace pyrolume::test
