#include "image/DisplayTransform.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "shared/view_transform.h"
#include "util/Error.h"
#include "util/Suggest.h"

namespace pyrolume {

namespace {

// BT.709 / sRGB relative luminance of linear RGB.
double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// The scene-linear grey value that `view` shows at the encoded display level
// `level`: bisection in log2 over ±kAutoExposureLimit stops (every view is
// non-decreasing on greys; tests/unit/image_view_transform_test.cpp checks).
double grey_for_display_level(double level, ViewTransform view) {
  double lo = -kAutoExposureLimit, hi = kAutoExposureLimit;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    const float g = float(std::exp2(mid));
    (display_encode(glm::vec3(g), view).y < level ? lo : hi) = mid;
  }
  return std::exp2(0.5 * (lo + hi));
}

}  // namespace

static_assert(std::size(kViewTransforms) == display::VIEW_COUNT, "every film.view name has a shader view, and back");

uint32_t view_shader_id(ViewTransform view) {
  switch (view) {
    case ViewTransform::Standard: return display::VIEW_STANDARD;
    case ViewTransform::AgXPunchy: return display::VIEW_AGX_PUNCHY;
    case ViewTransform::Filmic: return display::VIEW_FILMIC;
    case ViewTransform::AgX: break;
  }
  return display::VIEW_AGX;
}

glm::vec3 display_encode(glm::vec3 exposed, ViewTransform view) { return display::view_display(exposed, view_shader_id(view)); }

std::vector<unsigned char> display_rgb8(const Image& img, double exposure_stops, ViewTransform view) {
  const double scale = std::exp2(exposure_stops);
  const display::uint id = view_shader_id(view);
  std::vector<unsigned char> bytes(img.rgb.size());
  for (size_t i = 0; i + 2 < img.rgb.size(); i += 3) {
    // Scaled in double, rounded once to float: the arithmetic PNG output always had.
    const glm::vec3 exposed(float(double(img.rgb[i]) * scale), float(double(img.rgb[i + 1]) * scale),
                            float(double(img.rgb[i + 2]) * scale));
    const glm::vec3 v = display::view_display(exposed, id);
    for (int c = 0; c < 3; ++c) bytes[i + size_t(c)] = static_cast<unsigned char>(std::lround(255.0f * v[c]));
  }
  return bytes;
}

std::string film_look_warning(const Image& img, double exposure_stops, ViewTransform view, bool clips,
                              const FilmCause& cause) {
  const std::vector<unsigned char> bytes = display_rgb8(img, exposure_stops, view);
  size_t black = 0, clipped = 0;
  const size_t pixels = bytes.size() / 3;
  for (size_t i = 0; i + 2 < bytes.size(); i += 3) {
    const unsigned char hi = std::max({bytes[i], bytes[i + 1], bytes[i + 2]});
    black += hi <= 1;
    clipped += hi == 255;
  }
  if (pixels == 0) return "";
  char line[320];
  if (double(black) >= kBlackFilmFraction * double(pixels)) {
    const int n = std::snprintf(line, sizeof line, "the image is almost entirely black (%.1f %% of pixels at most 1/255 at exposure %+.2f EV): ",
                                100.0 * double(black) / double(pixels), exposure_stops);
    std::string w(line, size_t(std::max(n, 0)));
    if (!cause.unlit.empty()) return w + cause.unlit;
    const AutoExposure a = auto_exposure(img, view);
    if (a.lit_pixels == 0)
      return w + "no light reaches the camera (every pixel is 0): check that something is in view" +
             (cause.emits ? " and hot enough to glow" : " and lit");
    if (!(a.stops > exposure_stops))
      return w + "what light there is falls on few pixels (" + std::to_string(a.lit_pixels) +
             " lit): check that the subject is in view";
    std::snprintf(line, sizeof line, "its light is too dim for this exposure; --exposure %+.1f (or --exposure auto) shows it%s",
                  a.stops, cause.emits ? ", as does a larger emission.scale" : ", as do brighter lights");
    return w + line;
  }
  if (clips && double(clipped) >= kClippedFilmFraction * double(pixels)) {
    std::snprintf(line, sizeof line,
                  "the image is almost entirely clipped (%.1f %% of pixels have a channel at 255 at exposure %+.2f "
                  "EV): lower --exposure (or use --exposure auto)",
                  100.0 * double(clipped) / double(pixels), exposure_stops);
    return line;
  }
  return "";
}

AutoExposure auto_exposure(const Image& img, ViewTransform view) {
  std::vector<double> lit;
  lit.reserve(img.pixel_count());
  for (size_t i = 0; i + 2 < img.rgb.size(); i += 3) {
    const double y = luminance(&img.rgb[i]);
    if (std::isfinite(y) && y > 0.0) lit.push_back(y);
  }
  AutoExposure a;
  a.lit_pixels = lit.size();
  if (lit.empty()) return a;
  // Nearest rank: the smallest value with at least p % of the lit pixels at or below it.
  const size_t rank = size_t(std::ceil(kAutoExposurePercentile / 100.0 * double(lit.size())));
  const size_t k = std::clamp<size_t>(rank, 1, lit.size()) - 1;
  std::nth_element(lit.begin(), lit.begin() + std::ptrdiff_t(k), lit.end());
  a.percentile_luminance = lit[k];
  const double target = grey_for_display_level(kAutoExposureLevel, view);
  a.stops = std::clamp(std::log2(target / a.percentile_luminance), -kAutoExposureLimit, kAutoExposureLimit);
  return a;
}

std::string exposure_problem(const std::string& text) {
  if (text == "auto") return "";
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size() || !std::isfinite(v))
    return "expected a number of stops or \"auto\", got \"" + text + "\"";
  if (std::abs(v) > kMaxExposureStops)
    return "must be within ±" + std::to_string(int(kMaxExposureStops)) + " stops, got " + text;
  return "";
}

std::string view_problem(const std::string& text) {
  return view_from_name(text) ? "" : not_one_of(text, view_names(), /*suggest=*/true);
}

std::optional<ViewTransform> parse_view(const std::string& text, const std::string& flag) {
  if (text.empty()) return std::nullopt;  // not given
  const std::optional<ViewTransform> view = view_from_name(text);
  if (!view) throw input_error(flag, "", view_problem(text));
  return view;
}

ExposureOverride parse_exposure(const std::string& text, const std::string& flag) {
  ExposureOverride e;
  if (text.empty()) return e;  // not given
  if (const std::string why = exposure_problem(text); !why.empty()) throw input_error(flag, "", why);
  if (text == "auto") e.automatic = true;
  else e.stops = std::stod(text);
  return e;
}

double DisplayExposure::stops(const Film& film, const Image& image, std::ostream* log) {
  if (cli_.stops) return *cli_.stops;
  if (!automatic(film)) return film.exposure;
  if (!auto_) {
    auto_ = auto_exposure(image, film.view);
    if (log) *log << auto_exposure_line(*auto_) << "\n";
  }
  return auto_->stops;
}

std::string auto_exposure_line(const AutoExposure& a) {
  char line[160];
  if (a.lit_pixels == 0)
    std::snprintf(line, sizeof line, "pyrolume: auto exposure: %+.2f EV (the image is black)", a.stops);
  else
    std::snprintf(line, sizeof line, "pyrolume: auto exposure: %+.2f EV (%gth percentile luminance %.4g of %zu lit pixels)",
                  a.stops, kAutoExposurePercentile, a.percentile_luminance, a.lit_pixels);
  return line;
}

}  // namespace pyrolume
