#include "render/SceneChecks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "color/Blackbody.h"
#include "color/EmissionModel.h"
#include "light/AnalyticLights.h"
#include "util/Error.h"
#include "util/Math.h"

namespace pyrolume {
namespace {

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}


// The brightest channel a temperature-driven emission takes between 100 K
// (the lowest the renderers evaluate) and hottest_k (the grid's hottest
// voxel, at most 1e6 K, where they clamp): "physical" and "stefan_boltzmann"
// grow with T, "chromaticity" and "peak" are normalised curves, so the
// range is sampled every 2 % of temperature, its top included.
double brightest_blackbody(const Emission& e, double hottest_k) {
  hottest_k = std::min(hottest_k, kEmissionMaxK);
  double best = 0.0;
  for (double T = kEmissionMinK; T < hottest_k; T *= 1.02) best = std::max(best, max3(color::blackbody_rgb(T, e.blackbody, e.observer, e.adapt_to_k)));
  return std::max(best, max3(color::blackbody_rgb(hottest_k, e.blackbody, e.observer, e.adapt_to_k)));
}

void check_emitted_radiance(const std::string& file, const std::string& at, double scale, double brightest,
                            const std::string& what) {
  const double radiance = scale * brightest;
  if (!(radiance <= double(kMaxEmittedRadiance)))
    throw input_error(file, at + ".emission.scale",
                      "emission.scale " + sci(scale) + " × " + what + " (" + sci(brightest) + ") gives radiance " +
                          sci(radiance) + ", beyond " + sci(kMaxEmittedRadiance) +
                          ", the most a render can sum in float without overflowing; lower emission.scale");
}

// Whether v, as the GPU stores it (in float), is within kMaxEmittedRadiance:
// a light of exactly 1e12 is accepted (1e12 rounds to 1e12f). False for NaN.
bool within_emission_bound(double v) {
  return v <= double(std::numeric_limits<float>::max()) && float(v) <= kMaxEmittedRadiance;
}

// An analytic light's value (scale × rgb, or scale × the luminance-1
// blackbody colour), and a disc sun's radiance, within kMaxEmittedRadiance:
// the bound media have, so that no sample a light gives can overflow float.
void check_light_value(const std::string& file, size_t index, const Light& l) {
  const std::string at = "lights[" + std::to_string(index) + "]";
  const char* value_key = l.type == Light::Type::Distant  ? "irradiance"
                          : l.type == Light::Type::Sphere ? "radiance"
                                                          : "intensity";
  const double value = max3(light_value(l));
  if (!within_emission_bound(value)) {
    // Name the key that carries the excess: the rgb value when it alone is
    // past the bound, else scale.
    const bool rgb_alone = l.rgb && !within_emission_bound(max3(*l.rgb));
    const std::string what = l.rgb ? std::string(value_key) + " (" + sci(max3(*l.rgb)) + ")"
                                   : "the luminance-1 colour of temperature_k (" + sci(value / l.scale) + ")";
    throw input_error(file, at + "." + (rgb_alone ? value_key : "scale"),
                      "scale " + sci(l.scale) + " × " + what + " gives " + sci(value) + ", beyond " +
                          sci(kMaxEmittedRadiance) + ", the most a render can sum in float without overflowing; lower " +
                          (rgb_alone ? value_key : "scale"));
  }
  if (l.type != Light::Type::Distant || l.is_delta()) return;
  const double radiance = max3(disc_radiance(l));
  if (!within_emission_bound(radiance))
    throw input_error(file, at + ".angle_deg",
                      "the disc's radiance, irradiance / (π sin²(angle_deg/2)), is " + sci(radiance) + ", beyond " +
                          sci(kMaxEmittedRadiance) + ", the most a render can sum in float without overflowing; "
                          "widen angle_deg or lower irradiance");
}

}  // namespace

void check_scene_ranges(const Scene& scene) {
  const std::string file = scene.file.string();
  for (size_t i = 0; i < scene.lights.size(); ++i) check_light_value(file, i, scene.lights[i]);
  for (size_t i = 0; i < scene.media.size(); ++i) {
    const Medium& m = scene.media[i];
    const std::string at = "media[" + std::to_string(i) + "]";
    const bool grid = m.type == Medium::Type::Vdb;
    const double density_scale = grid ? m.density_scale : 1.0;
    if (max3(m.sigma_a + m.sigma_s) * density_scale > kMaxSigma)
      throw input_error(file, at + (grid ? ".density_scale" : ".sigma_a"),
                        "σa + σs" + std::string(grid ? " × density_scale" : "") + " reaches " +
                            sci(max3(m.sigma_a + m.sigma_s) * density_scale) + " per unit, beyond " + sci(kMaxSigma));
    const Emission& e = m.emission;
    if (!e.emits()) continue;
    // A grid's temperatures are known once it is loaded: check_loaded_medium.
    if (e.rgb) check_emitted_radiance(file, at, e.scale, max3(*e.rgb), "emission.rgb");
    else if (e.temperature_k)
      check_emitted_radiance(file, at, e.scale,
                             max3(color::blackbody_rgb(*e.temperature_k, e.blackbody, e.observer, e.adapt_to_k)),
                             "the blackbody colour of emission.temperature_k");
  }
}

void check_loaded_medium(const Scene& scene, size_t medium, const StoredVolume& volume) {
  check_majorant_depth(scene, medium, volume.density.grid);
  const Medium& m = scene.media[medium];
  const Emission& e = m.emission;
  if (!e.emits() || !e.is_grid || !volume.temperature || volume.temperature->grid.empty()) return;
  const DenseGrid& t = volume.temperature->grid;
  const TemperatureMapping& map = m.temperature;
  const double hottest_k = map.hottest_kelvin(t.min_value, t.max_value);
  if (!(hottest_k > map.cutoff_k)) return;  // nothing glows (the loader warns)
  char what[160];
  std::snprintf(what, sizeof what, "the brightest %s blackbody colour up to the grid's hottest voxel, %.4g K",
                color::to_string(e.blackbody), std::min(hottest_k, kEmissionMaxK));
  check_emitted_radiance(scene.file.string(), "media[" + std::to_string(medium) + "]", e.scale,
                         brightest_blackbody(e, hottest_k), what);
}

void check_majorant_depth(const Scene& scene, size_t medium, const DenseGrid& density) {
  if (density.empty()) return;
  const Medium& m = scene.media[medium];
  const double max_rho = density.max_texel();
  const double sigma_maj = max3(m.sigma_a + m.sigma_s) * m.density_scale * max_rho;
  glm::dvec3 lo, hi;
  density.world_bounds(lo, hi);
  const double diagonal = glm::length(hi - lo);
  const double depth = sigma_maj * diagonal;
  if (!(depth <= kMaxMajorantDepth))
    throw input_error(scene.file.string(), "media[" + std::to_string(medium) + "].density_scale",
                      "the grid's majorant optical depth is " + sci(depth) + " (σt up to " + sci(sigma_maj) +
                          " per unit across " + sci(diagonal) + " units): a ray through it would take that many "
                          "tracking steps, more than " + sci(kMaxMajorantDepth) +
                          "; lower density_scale (or sigma_a, sigma_s)");
}

}  // namespace pyrolume
