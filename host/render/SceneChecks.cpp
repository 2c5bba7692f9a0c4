#include "render/SceneChecks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "color/Blackbody.h"
#include "shared/gpu_types.h"
#include "util/Error.h"

namespace pyrolume {
namespace {

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

double max3(const glm::dvec3& v) { return std::max({v.x, v.y, v.z}); }

// The brightest channel a temperature-driven emission can take, over the
// temperatures the renderers evaluate (100 K to 1e6 K, where they clamp):
// "physical" grows with T, so its maximum is at the top; "seed" and "peak"
// are normalised curves, sampled every 2 % of temperature.
double brightest_blackbody(const Emission& e) {
  double best = 0.0;
  for (double T = 100.0; T < 1e6; T *= 1.02) best = std::max(best, max3(color::blackbody_rgb(T, e.blackbody, e.observer, e.adapt_to_k)));
  return std::max(best, max3(color::blackbody_rgb(1e6, e.blackbody, e.observer, e.adapt_to_k)));
}

}  // namespace

void check_scene_ranges(const Scene& scene) {
  const std::string file = scene.file.string();
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
    double brightest = 0.0;
    std::string what;
    if (e.rgb) {
      brightest = max3(*e.rgb);
      what = "emission.rgb";
    } else if (e.temperature_k) {
      brightest = max3(color::blackbody_rgb(*e.temperature_k, e.blackbody, e.observer, e.adapt_to_k));
      what = "the blackbody colour of emission.temperature_k";
    } else if (e.is_grid) {
      brightest = brightest_blackbody(e);
      what = std::string("the brightest ") + color::to_string(e.blackbody) + " blackbody colour up to 1e6 K";
    }
    const double radiance = e.scale * brightest;
    if (!(radiance <= double(gpu::MAX_EMITTED_RADIANCE)))
      throw input_error(file, at + ".emission.scale",
                        "emission.scale " + sci(e.scale) + " × " + what + " (" + sci(brightest) + ") gives radiance " +
                            sci(radiance) + ", beyond " + sci(gpu::MAX_EMITTED_RADIANCE) +
                            ", the most a render can sum in float without overflowing; lower emission.scale");
  }
}

void check_majorant_depth(const Scene& scene, size_t medium, const DenseGrid& density) {
  if (density.empty()) return;
  const Medium& m = scene.media[medium];
  double max_rho = 0.0;
  for (float v : density.values) max_rho = std::max(max_rho, double(v));
  const double sigma_bar = max3(m.sigma_a + m.sigma_s) * m.density_scale * max_rho;
  glm::dvec3 lo, hi;
  density.world_bounds(lo, hi);
  const double diagonal = glm::length(hi - lo);
  const double depth = sigma_bar * diagonal;
  if (!(depth <= kMaxMajorantDepth))
    throw input_error(scene.file.string(), "media[" + std::to_string(medium) + "].density_scale",
                      "the grid's majorant optical depth is " + sci(depth) + " (σt up to " + sci(sigma_bar) +
                          " per unit across " + sci(diagonal) + " units): a ray through it would take that many "
                          "tracking steps, more than " + sci(kMaxMajorantDepth) +
                          "; lower density_scale (or sigma_a, sigma_s)");
}

}  // namespace pyrolume
