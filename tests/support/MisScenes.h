#pragma once
// Scenes for next-event estimation and MIS (docs/mis.md), shared by the CPU
// reference tests and the GPU tests: an emissive, scattering grid above a
// diffuse plane under a dim uniform sky, and an emissive scattering grid on
// its own. Each can be rendered with any light strategy.
#include <filesystem>
#include <string>

#include <cstdio>

#include <gtest/gtest.h>

#include "image/ImageIo.h"
#include "render/Render.h"
#include "support/Stats.h"
#include "support/AnalyticScenes.h"
#include "support/SurfaceScenes.h"
#include "support/VdbScenes.h"

namespace pyrolume::test {

enum class Strategy { Bsdf, Mis, LightOnly };

inline void set_strategy(Scene& s, Strategy k) {
  s.integrator.emission_estimator = EmissionEstimator::Collision;
  s.integrator.mis = k != Strategy::Bsdf;
  s.integrator.light_only = k == Strategy::LightOnly;
}

// A scene that writes its strategy out must render with it: light selection
// may turn light sampling off where nothing is there to light (docs/mis.md),
// and a MIS test would then go on passing while testing BSDF sampling.
inline void expect_strategy_as_written(const Scene& s, const RenderResult& r) {
  if (s.integrator.light_only) EXPECT_EQ(r.light_strategy, "light_only") << s.file;
  else if (s.integrator.mis) EXPECT_EQ(r.light_strategy, *s.integrator.mis ? "mis" : "bsdf") << s.file;
}

// A uniform lat-long sky of radiance `value` (written once per folder).
inline std::filesystem::path write_uniform_sky(const std::filesystem::path& dir, glm::vec3 value) {
  const auto exr = dir / "uniform_sky.exr";
  write_image(exr, uniform_image(8, 4, value));
  return exr;
}

// A small hot constant box of smoke (5³ voxels of 0.1, temperature 2500 K,
// σa 2, σs 1.5 or 0, g 0.3) floating above a white-ish plane, Y up, seen from
// above at an angle so most pixels are plane lit by the fire; optional dim
// uniform sky. Light sampling alone has infinite variance inside a scattering
// emitter (1/r² at a vertex next to the light point), so its tests use
// scattering = false. `dir` holds the scene's files.
inline Scene fire_over_plane_scene(const std::filesystem::path& dir, Strategy k, bool sky, bool scattering = true,
                                   int width = 24, int height = 18, int spp = 256) {
  Scene s = analytic_base_scene(width, height, spp);
  s.camera.position = {0, 2.2, -3.2};
  s.camera.look_at = {0, -0.2, 0};
  s.integrator.max_depth = 4;
  const Lattice l{0.1, {-0.2, 0.4, -0.2}};
  const VoxelBox box{{0, 0, 0}, {4, 4, 4}};
  const auto vdb = dir / "fire_box.vdb";
  if (!std::filesystem::exists(vdb))
    write_constant_box_vdb(vdb, l, box, 1.0f, TemperatureBox{l, box, 2500.0f});
  s.media.push_back(vdb_medium("fire", vdb, glm::dvec3(2.0), glm::dvec3(scattering ? 1.5 : 0.0), 0.3, std::nullopt,
                               6.0, true));
  s.shapes.push_back(plane_shape({0, -0.3, 0}, {0, 1, 0}, {0, 0}, glm::dvec3(0.8, 0.7, 0.6)));
  if (sky) s.environment = Environment{write_uniform_sky(dir, glm::vec3(0.05f, 0.07f, 0.1f)), 1.0, 0.0};
  set_strategy(s, k);
  return s;
}

// An emissive, strongly scattering grid (albedo 0.75, g −0.2) seen from
// outside: its light reaches the camera mostly after scattering inside it.
inline Scene scattering_fire_scene(const std::filesystem::path& dir, Strategy k, int width = 16, int height = 16,
                                   int spp = 256) {
  Scene s = analytic_base_scene(width, height, spp);
  s.camera.position = {0, 0, -2.2};
  s.integrator.max_depth = 16;
  const Lattice l{0.1, {-0.4, -0.4, -0.4}};
  const VoxelBox box{{0, 0, 0}, {8, 8, 8}};
  const VoxelBox hot{{2, 2, 2}, {6, 6, 6}};  // a hot core inside the smoke
  const auto vdb = dir / "scattering_fire.vdb";
  if (!std::filesystem::exists(vdb))
    write_constant_box_vdb(vdb, l, box, 1.0f, TemperatureBox{l, hot, 3000.0f});
  s.media.push_back(vdb_medium("fire", vdb, glm::dvec3(0.5), glm::dvec3(1.5), -0.2, std::nullopt, 4.0, true));
  s.media.back().temperature.cutoff_k = 500.0;
  set_strategy(s, k);
  return s;
}

// The furnace: a white diffuse sphere (albedo 1) in a uniform white sky, n
// next-event samples per surface vertex, optionally the ratio-tracked
// continuation; exactly 1 everywhere.
inline Scene furnace_sphere_scene(const std::filesystem::path& dir, Strategy k, int surface_light_samples,
                                  bool ratio_tracked_continuation = false) {
  Scene s = analytic_base_scene(16, 16, 64);
  s.integrator.max_depth = 64;
  s.integrator.surface_light_samples = surface_light_samples;
  s.integrator.ratio_tracked_continuation = ratio_tracked_continuation;
  s.shapes.push_back(sphere_shape({0, 0, 0}, 1.0, glm::dvec3(1.0)));
  s.environment = Environment{write_uniform_sky(dir, glm::vec3(1.0f)), 1.0, 0.0};
  set_strategy(s, k);
  return s;
}

// The furnace with a medium around the surface: a white diffuse sphere
// (albedo 1, radius 0.6) inside a purely scattering smoke sphere (σa = 0,
// radius 1) in a uniform white sky, 3 next-event samples per surface vertex
// and the ratio-tracked continuation on or off: energy is conserved, L = 1
// everywhere, and the continuation's rays are tracked through the smoke.
inline Scene smoky_furnace_scene(const std::filesystem::path& dir, Strategy k, bool ratio_tracked_continuation) {
  Scene s = analytic_base_scene(16, 16, 64);
  s.integrator.max_depth = 1000;
  s.integrator.surface_light_samples = 3;
  s.integrator.ratio_tracked_continuation = ratio_tracked_continuation;
  s.shapes.push_back(sphere_shape({0, 0, 0}, 0.6, glm::dvec3(1.0)));
  s.media.push_back(homogeneous_sphere("smoke", {0, 0, 0}, 1.0, glm::dvec3(0.0), glm::dvec3(2.0), 0.3, std::nullopt));
  s.environment = Environment{write_uniform_sky(dir, glm::vec3(1.0f)), 1.0, 0.0};
  set_strategy(s, k);
  return s;
}

// --------------------------------------------------------------- checks ----

// Two renders of the same scene converge to the same image (pooled z-test,
// bias formula of docs/testing.md); prints the report.
inline void expect_same_image(const RenderResult& a, const RenderResult& b, double tolerance, const char* what) {
  ZTestReport z = ztest_images(a, b, pooled(tolerance));
  EXPECT_TRUE(z.ok) << what << ": " << z.summary();
  std::printf("%s: %s\n", what, z.summary().c_str());
}

// On the fire over a plane under a sky (every strategy has finite variance
// there), MIS at 256 spp and light sampling only at 256 spp converge to BSDF
// sampling only at bsdf_spp, with one next-event sample per surface vertex
// and with three (their MIS weights count the samples) and the ratio-tracked
// continuation. render(scene) is one backend's render; `who` prefixes the reports.
template <class Render>
void expect_strategies_agree(Render render, const std::filesystem::path& dir, int bsdf_spp, const std::string& who) {
  auto scene = [&](Strategy k, int spp, int light_samples) {
    Scene s = fire_over_plane_scene(dir, k, true, false, 24, 18, spp);
    s.integrator.surface_light_samples = light_samples;
    s.integrator.ratio_tracked_continuation = light_samples > 1;
    return s;
  };
  const RenderResult bsdf = render(scene(Strategy::Bsdf, bsdf_spp, 1));
  for (int n : {1, 3}) {
    const std::string samples = n == 1 ? "" : ", " + std::to_string(n) + " light samples, ratio-tracked continuation";
    expect_same_image(render(scene(Strategy::Mis, 256, n)), bsdf, 0.02, (who + "MIS vs BSDF only" + samples).c_str());
    expect_same_image(render(scene(Strategy::LightOnly, 256, n)), bsdf, 0.02,
                      (who + "light only vs BSDF only" + samples).c_str());
  }
}

// Σ over the pixel-channels of the rows from `first_row` down of the
// per-sample variance: the plane in front of the fire in fire_over_plane_scene.
inline double lower_rows_variance(const RenderResult& r, int first_row) {
  double v = 0.0;
  for (int y = first_row; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = (size_t(y) * r.width + x) * 3 + c;
        v += sample_variance(r.sum[i], r.sum_sq[i], r.spp);
      }
  return v;
}

}  // namespace pyrolume::test
