#pragma once
// Display output: the linear render -> 8-bit sRGB through exposure and the view
// transform of shaders/shared/view_transform.h (the code the preview's display
// shader runs too), and auto exposure. PNG output goes through display_rgb8;
// so should anything that judges what a user will see (docs/view-transform.md).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "image/Image.h"
#include "scene/Scene.h"

namespace pyrolume {

// The view's VIEW_* number in shaders/shared/view_transform.h (what the
// preview's display shader is given).
uint32_t view_shader_id(ViewTransform view);

// One colour: sRGB-encoded display values in [0, 1] of linear sRGB radiance
// that is already scaled by 2^exposure.
glm::vec3 display_encode(glm::vec3 exposed, ViewTransform view);

// The whole image as the PNG shows it: interleaved 8-bit sRGB RGB, row 0 = top,
// byte = round(255 · display_encode(L · 2^exposure_stops)). With Standard this
// is exactly what PNG output was before views existed.
std::vector<unsigned char> display_rgb8(const Image& img, double exposure_stops, ViewTransform view);

// Auto exposure (docs/view-transform.md): the exposure that puts the
// kAutoExposurePercentile-th percentile of the luminance of the lit pixels
// (finite luminance > 0) where `view` shows a grey pixel at the sRGB-encoded
// display level kAutoExposureLevel. An image without lit pixels gets 0.
inline constexpr double kAutoExposurePercentile = 99.0;
inline constexpr double kAutoExposureLevel = 0.8;  // 204/255
inline constexpr double kAutoExposureLimit = kMaxExposureStops;  // |stops| at most
struct AutoExposure {
  double stops = 0.0;
  double percentile_luminance = 0.0;  // 0 when no pixel is lit
  size_t lit_pixels = 0;
};
AutoExposure auto_exposure(const Image& img, ViewTransform view);

// An `--exposure` value: a finite number of stops or "auto". Empty text: no
// override. Anything else: InputError naming `flag`.
struct ExposureOverride {
  bool automatic = false;
  std::optional<double> stops;
};
ExposureOverride parse_exposure(const std::string& text, const std::string& flag = "--exposure");
// Why `text` is no exposure value, "" when it is one: "auto", or a finite
// number of stops within ±kMaxExposureStops (the empty text is none).
std::string exposure_problem(const std::string& text);

// A `--view` value (render, preview): one of film.view's names, overriding
// film.view on every frame. Empty text: no override (nullopt). Anything else:
// InputError naming `flag`, with a "did you mean" for a near miss.
std::optional<ViewTransform> parse_view(const std::string& text, const std::string& flag = "--view");
// Why `text` is no view name, "" when it is one (the empty text is none).
std::string view_problem(const std::string& text);

// The exposure display output uses, frame after frame: the override's, else
// film.exposure (evaluated at the frame by the caller); "auto" from either is
// computed from the first image it sees and kept, so that a sequence does not
// flicker. The first time it chooses, it writes auto_exposure_line() to `log`.
class DisplayExposure {
 public:
  explicit DisplayExposure(ExposureOverride cli = {}) : cli_(cli) {}
  bool automatic(const Film& film) const { return cli_.automatic || (!cli_.stops && film.exposure_auto); }
  double stops(const Film& film, const Image& image, std::ostream* log = nullptr);
  const std::optional<AutoExposure>& chosen_auto() const { return auto_; }
  void forget_auto() { auto_.reset(); }  // the next image chooses again

 private:
  ExposureOverride cli_;
  std::optional<AutoExposure> auto_;
};

// A render a user will surely be disappointed by, judged on what the display
// shows (exposure and view applied): "" unless it is almost entirely black
// (at least kBlackFilmFraction of the pixels have every channel <= 1/255) or,
// for display output (`clips`: PNG), almost entirely clipped (at least
// kClippedFilmFraction of the pixels have a channel at 255). Otherwise one line
// saying so, naming the cause that holds and a change that would show more:
// `unlit` (nothing in the scene gives light: render/SceneSetup's
// nothing_emits), else light too dim for the exposure (the exposure that
// shows it; emission.scale only when `emits`), else no light at all reaching
// the camera.
inline constexpr double kBlackFilmFraction = 0.995;
inline constexpr double kClippedFilmFraction = 0.95;
struct FilmCause {
  std::string unlit;  // non-empty: why nothing gives light
  bool emits = true;  // some medium emits
};
std::string film_look_warning(const Image& img, double exposure_stops, ViewTransform view, bool clips,
                              const FilmCause& cause = {});

// "pyrolume: auto exposure: +N.NN EV (...)": what was chosen and from what.
std::string auto_exposure_line(const AutoExposure& a);

}  // namespace pyrolume
