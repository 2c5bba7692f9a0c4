// The Vulkan backend with grid (vdb) media (issue 5 on the GPU, and issue 4's
// mismatched-lattice test): delta tracking against per-cell majorants, both
// emission estimators, against closed forms, against each other, and against
// the CPU reference. Mirrors tests/unit/cpu_vdb_test.cpp; every VDB is written
// by the test (tests/support/VdbScenes.h). Validation layers are on: any
// validation message fails the test.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "color/Blackbody.h"
#include "render/Backend.h"
#include "render/cpu/CpuRenderer.h"
#include "render/cpu/Intersect.h"
#include "scene/MediumVolume.h"
#include "support/VulkanFixture.h"
#include "support/AnalyticScenes.h"
#include "support/Stats.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "render/vulkan/GpuScene.h"
#include "volume/StoredVolume.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

using test::ZTestOptions;
using test::ZTestReport;

using test::settings_for;

// Absorption-estimator samples are Bernoulli-like (Le or background): pool the
// variance over 3×3 (Stats.h explains).
ZTestOptions pooled(double tolerance = 0.005) {
  ZTestOptions o;
  o.pool3x3 = true;
  o.bias_tolerance = tolerance;
  return o;
}

double per_sample(double count, const RenderResult& r) { return count / (double(r.width) * r.height * r.spp); }

const char* kEstimators[] = {"absorption", "collision"};

// The constant box (lat, box, c, dir, constant_box_scene, field) comes from
// test::ConstantBoxSetup, shared with cpu_vdb_test.
class VulkanVdb : public test::VulkanFixture, public test::ConstantBoxSetup {
 protected:


  VulkanVdb() : test::ConstantBoxSetup("vulkan_vdb") {}

  // The shipped fire (assets/scenes/fire.json) at a test's film size.
  static Scene shipped_fire(int width, int height, int spp) {
    Scene s = load_scene(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/scenes/fire.json");
    s.film.width = width;
    s.film.height = height;
    s.film.spp = spp;
    return s;
  }

  // The lookup-bound fire (docs/benchmarks.md): dense and scattering, BSDF
  // sampling with the absorption estimator, long paths.
  static Scene lookup_bound_fire(int width, int height, int spp) {
    Scene s = shipped_fire(width, height, spp);
    s.integrator.max_depth = 16;
    s.integrator.emission_estimator = "absorption";
    s.media[0].density_scale = 8.0;
    s.media[0].sigma_a = glm::dvec3(0.5);
    s.media[0].sigma_s = glm::dvec3(4.0);
    return s;
  }

  // Both estimators against the exact image; returns the last render.
  RenderResult expect_closed_form(Scene s, const std::function<glm::dvec3(int, int)>& exact, const char* what,
                                  double tolerance = 0.005) {
    RenderResult r;
    for (const char* est : kEstimators) {
      s.integrator.emission_estimator = est;
      r = render(s);
      ZTestReport rep = test::ztest_against_exact(r, exact, pooled(tolerance));
      EXPECT_TRUE(rep.ok) << what << " [" << est << "] " << rep.summary();
      std::printf("%s [%s]: %s; lookups/sample %.2f, events/sample %.3f, %.2f s\n", what, est, rep.summary().c_str(),
                  per_sample(r.density_lookups, r), per_sample(r.events, r), r.seconds);
      EXPECT_LE(r.events, r.density_lookups) << "a real collision without a density lookup";
    }
    return r;
  }
};

// A constant grid equals the closed form of the field it really is (the
// constant in the centre box, the separable ramp to 0 around it), seen
// obliquely so faces, edges and corners of the ramp are in view (cpu_vdb_test
// explains). Fails for a wrong density_scale, a half-voxel shift, a
// transposed axis or clipping to the wrong box. And the check can fail: the
// same render against the closed form of a 3 % denser grid is rejected.
TEST_F(VulkanVdb, ConstantGridMatchesClosedFormIncludingEdgeRamp) {
  Scene s = constant_box_scene(32, 32, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  RenderResult r = expect_closed_form(s, test::constant_box_exact(s, field()), "constant grid");
  test::ConstantBoxField denser = field();
  denser.c *= 1.03;
  ZTestReport wrong = test::ztest_against_exact(r, test::constant_box_exact(s, denser), pooled());
  EXPECT_FALSE(wrong.ok) << "a 3 % denser closed form was accepted: " << wrong.summary();
  std::printf("deliberately wrong (3 %% denser): %s\n", wrong.summary().c_str());
}

// Scattering as pure extinction (max_depth 0): L = (σa/σt)·Le·(1 − e^{−σt τ}) + bg·e^{−σt τ}.
TEST_F(VulkanVdb, ScatteringGridAtMaxDepthZeroIsExtinction) {
  Scene s = constant_box_scene(24, 24, 512, {0.5, 0.3, 0.2}, {0.6, 1.2, 2.0});
  s.integrator.max_depth = 0;
  expect_closed_form(s, test::constant_box_exact(s, field()), "max_depth 0");
}

// The whole scene (grid and camera) rotated and moved by the medium transform
// gives the unrotated closed form: rays are clipped to the ORIENTED texel box
// and the world→texel map carries the rotation.
TEST_F(VulkanVdb, RotatedGridMatchesUnrotatedClosedForm) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  auto exact = test::constant_box_exact(s, field());
  s.media[0].transform.rotate_deg = {20.0, 35.0, -15.0};
  s.media[0].transform.translate = {0.4, -0.3, 0.2};
  const glm::dmat4 M = medium_transform_matrix(s.media[0].transform);
  s.camera.position = glm::dvec3(M * glm::dvec4(s.camera.position, 1.0));
  s.camera.look_at = glm::dvec3(M * glm::dvec4(s.camera.look_at, 1.0));
  s.camera.up = glm::dvec3(M * glm::dvec4(s.camera.up, 0.0));
  expect_closed_form(s, exact, "rotated");
}

// A grid with a wide all-zero slab between two constant blocks (σ̄ = 0 cells
// with a fine majorant grid): the closed form holds, and the zero cells are
// skipped without lookups, so the majorant grid needs fewer lookups than the
// global majorant for the same image.
TEST_F(VulkanVdb, ZeroMajorantRegionsAreSkipped) {
  const test::VoxelBox wide{{-16, -5, -5}, {16, 5, 5}};
  auto value = [](int i, int, int) { return (i <= -7 || i >= 7) ? 0.75f : 0.0f; };
  test::write_vdb(dir / "gap.vdb", {test::make_float_grid("density", lat, wide, value)});
  Scene s = test::vdb_base_scene(32, 24, 512);
  s.camera.position = {0.5, 1.0, -4.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.fov_deg = 45.0;
  s.background = {0.05, 0.1, 0.2};
  s.media.push_back(test::vdb_medium("gap", dir / "gap.vdb", {0.8, 1.6, 3.2}, {0, 0, 0}, 0.0,
                                     glm::dvec3(1.0, 0.6, 0.3), 1.5));
  s.media[0].density_scale = 1.5;
  s.integrator.majorant_grid = glm::ivec3(35, 1, 1);  // 1-texel slabs: the middle ones are all zero
  const test::TrilinearVoxelField f(lat, wide, value);
  auto exact = test::exact_image(s, [&](const glm::dvec3& o, const glm::dvec3& d, int* sig) {
    if (sig) *sig = f.signature(o, d);
    return test::uniform_albedo_radiance(s, f.optical_depth(o, d));
  });
  RenderResult grid = expect_closed_form(s, exact, "zero gap (grid)");
  s.integrator.majorant = "global";
  RenderResult global = expect_closed_form(s, exact, "zero gap (global)");
  std::printf("zero gap: lookups/sample grid %.3f, global %.3f (ratio %.2f)\n", per_sample(grid.density_lookups, grid),
              per_sample(global.density_lookups, global), global.density_lookups / grid.density_lookups);
  EXPECT_LT(grid.density_lookups, global.density_lookups);
}

// No closed form with multiple scattering: the two estimators must converge to
// the same image (GPU vs GPU, independent seeds). A sparse explosion shell with
// chromatic σa/σs, anisotropic scattering and blackbody emission from its
// temperature grid, overlapping a homogeneous emissive sphere, under a
// coloured background.
TEST_F(VulkanVdb, EstimatorsAgreeOnScatteringChromaticTemperatureScene) {
  const test::Lattice shell_lat{0.07, {0.0, 0.0, 0.0}};
  Scene s = test::vdb_base_scene(32, 32, 1024);
  s.camera.position = {0.3, 0.4, -3.5};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.background = {0.1, 0.15, 0.3};
  s.integrator.max_depth = 8;
  s.media.push_back(test::vdb_medium("shell", test::write_explosion_shell_vdb(dir / "shell.vdb", shell_lat),
                                     {1.0, 1.5, 2.0}, {2.0, 1.5, 1.0}, 0.5, std::nullopt, 2.0, true));
  s.media[0].density_scale = 2.0;
  s.media[0].emission.blackbody = BlackbodyMode::Seed;
  s.media[0].temperature.cutoff_k = 800.0;
  s.media.push_back(test::homogeneous_sphere("core", {0.1, 0.0, 0.0}, 0.5, {0.5, 0.5, 0.5}, {0.5, 0.3, 0.1}, -0.3,
                                             glm::dvec3(0.2, 0.5, 1.0)));
  RenderResult r[2];
  for (int i = 0; i < 2; ++i) {
    s.integrator.emission_estimator = kEstimators[i];
    s.film.seed = 11 + 13 * i;
    r[i] = render(s);
    std::printf("%s: %.2f s, lookups/sample %.2f, events/sample %.3f\n", kEstimators[i], r[i].seconds,
                per_sample(r[i].density_lookups, r[i]), per_sample(r[i].events, r[i]));
  }
  ZTestReport rep = test::ztest_images(r[1], r[0], pooled(0.01));
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("collision vs absorption: %s\n", rep.summary().c_str());
  // The comparison can fail: 3 % more emission in one image is rejected.
  Scene brighter = s;
  for (Medium& m : brighter.media) m.emission.scale *= 1.03;
  brighter.integrator.emission_estimator = "collision";
  ZTestReport wrong = test::ztest_images(render(brighter), r[0], pooled(0.01));
  EXPECT_FALSE(wrong.ok) << "3 % more emission was accepted: " << wrong.summary();
  std::printf("deliberately wrong (3 %% brighter): %s\n", wrong.summary().c_str());
}

// The majorant grid and one global majorant give the same image, and on a
// sparse explosion shell (empty inside and in the corners) the grid saves
// density lookups: at the default resolution and at 16³ cells.
TEST_F(VulkanVdb, MajorantGridMatchesGlobalWithFewerLookups) {
  const test::Lattice shell_lat{0.05, {0.0, 0.0, 0.0}};
  Scene s = test::vdb_base_scene(32, 32, 512);
  s.camera.position = {0.3, 0.4, -4.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.background = {0.1, 0.15, 0.3};
  s.integrator.max_depth = 4;
  s.integrator.emission_estimator = "collision";
  s.media.push_back(test::vdb_medium("shell",
                                     test::write_explosion_shell_vdb(dir / "shell.vdb", shell_lat, 20.0, 30.0, 1.0f),
                                     {2.0, 2.5, 3.0}, {1.0, 1.0, 1.0}, 0.3, std::nullopt, 2.0, true));
  s.media[0].density_scale = 3.0;
  s.media[0].temperature.cutoff_k = 800.0;
  s.integrator.majorant = "global";
  s.film.seed = 5;
  const RenderResult global = render(s);
  s.integrator.majorant = "grid";
  s.film.seed = 6;
  const RenderResult grid_default = render(s);
  s.integrator.majorant_grid = glm::ivec3(16);
  s.film.seed = 7;
  const RenderResult grid16 = render(s);
  for (const RenderResult* g : {&grid_default, &grid16}) {
    ZTestReport rep = test::ztest_images(*g, global, pooled(0.01));
    EXPECT_TRUE(rep.ok) << rep.summary();
    std::printf("%s vs global: %s\n", g == &grid16 ? "grid 16^3" : "grid (default res)", rep.summary().c_str());
  }
  const double lg = per_sample(global.density_lookups, global), ld = per_sample(grid_default.density_lookups, grid_default),
               l16 = per_sample(grid16.density_lookups, grid16);
  std::printf("explosion shell lookups/sample: global %.2f, grid default %.2f (%.2fx fewer), grid 16^3 %.2f (%.2fx fewer); "
              "seconds %.2f / %.2f / %.2f\n",
              lg, ld, lg / ld, l16, lg / l16, global.seconds, grid_default.seconds, grid16.seconds);
  EXPECT_LT(ld, lg);
  EXPECT_LT(l16, ld);
  // The shell's own lookups are unavoidable; what a grid can save is the
  // empty interior (r < 20 voxels of 30): a bit under 2x here at 16^3.
  EXPECT_LT(l16, 0.75 * lg) << "a 16^3 majorant grid should skip the shell's empty interior";
}

// GPU vs the CPU reference on the procedural fire (assets/scenes/fire.json:
// collision estimator, scattering, blackbody emission from a temperature grid
// on another lattice) at low resolution. The CPU is the expensive side: few
// pixels and spp there, many on the GPU so its error is small.
TEST_F(VulkanVdb, AgreesWithCpuOnProceduralFire) {
  Scene s = shipped_fire(24, 16, 4096);
  s.film.seed = 3;
  const RenderResult gpu = render(s);
  Scene cs = s;
  cs.film.spp = 1536;
  cs.film.seed = 4;
  CpuRenderer cpu;
  const auto t0 = std::chrono::steady_clock::now();
  const RenderResult ref = cpu.render(cs, settings_for(cs), {});
  const double cpu_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(cpu.majorant_violations(), 0u);
  EXPECT_EQ(ref.nonfinite_samples, 0u);
  ZTestReport rep = test::ztest_images(gpu, ref, pooled());
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("fire GPU vs CPU: %s; GPU %.2f s, CPU %.2f s\n", rep.summary().c_str(), gpu.seconds, cpu_s);
  // The comparison can fail: the GPU image of a 3 % brighter fire is rejected.
  Scene brighter = s;
  brighter.film.spp = 1024;
  brighter.media[0].emission.scale *= 1.03;
  ZTestReport wrong = test::ztest_images(render(brighter), ref, pooled());
  EXPECT_FALSE(wrong.ok) << "3 % more emission was accepted: " << wrong.summary();
  std::printf("deliberately wrong (3 %% brighter): %s\n", wrong.summary().c_str());
}

// The free-flight loop's early exit (render.comp EARLY_EVENT_EXIT: the SIMD
// group leaves once half its lanes have their event, the rest go on at the
// next call) changes only the schedule: each path draws the same random
// numbers, so the image is the same bit for bit, on the lookup-bound shape
// of the shipped fire (dense, scattering, long flights) and with the
// absorption estimator's emission at absorptions.
TEST_F(VulkanVdb, EarlyEventExitRendersTheSameImageBitForBit) {
  Scene s = lookup_bound_fire(24, 32, 16);
  RenderSettings waiting = settings_for(s);
  waiting.early_event_exit = false;
  const RenderResult early = render(s), late = backend_->render(s, waiting, {});
  ASSERT_EQ(early.light_strategy, "bsdf");
  ASSERT_EQ(early.sum.size(), late.sum.size());
  size_t differing = 0;
  for (size_t i = 0; i < early.sum.size(); ++i)
    differing += early.sum[i] != late.sum[i] || early.sum_sq[i] != late.sum_sq[i];
  EXPECT_EQ(differing, 0u) << "of " << early.sum.size() << " channel sums";
  EXPECT_EQ(early.density_lookups, late.density_lookups);
  EXPECT_EQ(early.events, late.events);
  EXPECT_GT(early.events, 0.0);
}

// The wavefront prototype (PYROLUME_WAVEFRONT=1: track and event stages; 2:
// the event stage split in two) runs each path's code on the same random
// numbers in the same order as the megakernel: the same image bit for bit,
// on the fire over a ground with MIS (light rays, surfaces) and on the
// lookup-bound fire (BSDF sampling, no surfaces).
TEST_F(VulkanVdb, WavefrontRendersTheSameImageBitForBit) {
  Scene ground = load_scene(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/scenes/fire_ground.json");
  ground.film.width = 24;
  ground.film.height = 16;
  ground.film.spp = 8;
  const Scene lookup = lookup_bound_fire(16, 24, 8);
  struct Restore {
    ~Restore() { unsetenv("PYROLUME_WAVEFRONT"); }
  } restore;
  // Each mode once (each session compiles its stages: seconds on lavapipe).
  for (const auto& [s, mode] : {std::pair<const Scene*, const char*>{&ground, "1"}, {&lookup, "2"}}) {
    unsetenv("PYROLUME_WAVEFRONT");
    const RenderResult mega = render(*s);
    EXPECT_EQ(mega.light_strategy, s == &ground ? "mis" : "bsdf");
    EXPECT_GT(mega.events, 0.0);
    {
      setenv("PYROLUME_WAVEFRONT", mode, 1);
      const RenderResult wave = render(*s);
      ASSERT_EQ(wave.light_strategy, mega.light_strategy);
      ASSERT_EQ(wave.sum.size(), mega.sum.size());
      size_t differing = 0;
      for (size_t i = 0; i < wave.sum.size(); ++i)
        differing += wave.sum[i] != mega.sum[i] || wave.sum_sq[i] != mega.sum_sq[i];
      EXPECT_EQ(differing, 0u) << "of " << wave.sum.size() << " channel sums, " << s->file << ", mode " << mode;
      EXPECT_EQ(wave.density_lookups, mega.density_lookups) << mode;
      EXPECT_EQ(wave.events, mega.events) << mode;
      EXPECT_EQ(wave.spp, mega.spp) << mode;
    }
  }
}

// An all-zero grid and a grid with no active voxels render the background
// exactly, read no texel and have no events.
TEST_F(VulkanVdb, ZeroAndEmptyGridsRenderTheBackground) {
  Scene s = test::vdb_base_scene(16, 16, 8);
  s.background = {0.2, 0.4, 0.6};
  s.media.push_back(test::vdb_medium("zero", test::write_constant_box_vdb(dir / "zero.vdb", lat, box, 0.0f),
                                     {1, 1, 1}, {1, 1, 1}, 0.0, glm::dvec3(1.0)));
  s.media.push_back(
      test::vdb_medium("empty", test::write_empty_vdb(dir / "empty.vdb"), {1, 1, 1}, {1, 1, 1}, 0.0, glm::dvec3(1.0)));
  for (const char* majorant : {"grid", "global"})
    for (const char* est : kEstimators) {
      s.integrator.emission_estimator = est;
      s.integrator.majorant = majorant;
      RenderResult r = render(s);
      for (size_t i = 0; i < r.sum.size(); ++i)
        ASSERT_NEAR(r.sum[i] / r.spp, s.background[i % 3], 1e-6 * s.background[i % 3])  // float accumulation
            << est << " " << majorant << " at " << i;
      EXPECT_EQ(r.density_lookups, 0.0) << est << " " << majorant;
      EXPECT_EQ(r.events, 0.0) << est << " " << majorant;
    }
  // Each alone too (a scene whose only grid is empty has no grid at all on the GPU).
  for (int keep = 0; keep < 2; ++keep) {
    Scene one = s;
    one.media.erase(one.media.begin() + (1 - keep));
    RenderResult r = render(one);
    for (size_t i = 0; i < r.sum.size(); ++i) ASSERT_NEAR(r.sum[i] / r.spp, s.background[i % 3], 1e-6);
    EXPECT_EQ(r.density_lookups, 0.0);
  }
}

// Optical depth 1e4 per voxel: the background is blocked completely and every
// ray through the grid sees exactly Le; the closed form covers the silhouette.
//
// Regression test for two bugs this test found (fixed in render.comp): the
// texel box [0, dims] started half a texel before the zero padding's centre, so
// each ray made ~5000 null collisions (σ̄ = 1e5/unit) in a region where every
// lookup is 0; and the lane's single sample loop ran into llvmpipe's
// 65535-iterations-per-loop limiter, which dropped the unfinished samples of a
// pass silently (centre pixels read 15/64 of Le). Rays are now clipped to the
// trilinear support and the lane loop is split in two nested loops.
TEST_F(VulkanVdb, OpticalDepth1e4PerVoxelIsOpaque) {
  Scene s = constant_box_scene(20, 20, 64, {1e5 / 1.5 / 0.75, 1e5 / 1.5 / 0.75, 1e5 / 1.5 / 0.75}, {0, 0, 0});
  s.background = {3.0, 2.0, 1.0};
  expect_closed_form(s, test::constant_box_exact(s, field()), "opaque");
}

// A density of 1e-6 (a half subnormal as stored) with an 8000 K temperature
// grid covering the whole density texture: L = Le(8000 K)·(1 − e^{−σ τ}) with the
// STORED density; density_scale makes it visible so a bias can be resolved.
// Then, unscaled (σ̄ ~ 1e-6, Le ~ 1e6): no informative test, but finite.
TEST_F(VulkanVdb, TinyDensityWithHighTemperature) {
  const float rho = glm::unpackHalf1x16(glm::packHalf1x16(1e-6f));
  ASSERT_GT(rho, 0.0f);
  const test::TemperatureBox tb{{0.15, {0.01, 0.02, -0.03}}, {{-8, -6, -7}, {8, 6, 7}}, 8000.0f};
  Scene s = test::vdb_base_scene(24, 24, 512);
  s.camera.position = {2.0, 1.5, -4.0};
  s.camera.look_at = {0.1, 0.05, 0.0};
  s.media.push_back(test::vdb_medium("wisp", test::write_constant_box_vdb(dir / "wisp.vdb", lat, box, 1e-6f, tb),
                                     {1.0, 1.0, 1.0}, {0, 0, 0}, 0.0, std::nullopt, 3.0, true));
  s.media[0].density_scale = 1.5e6;
  const glm::dvec3 Le = 3.0 * color::blackbody_rgb(8000.0, BlackbodyMode::Seed);
  const test::ConstantBoxField f{lat, box, double(rho)};
  auto exact = test::exact_image(s, [&](const glm::dvec3& o, const glm::dvec3& d, int* sig) {
    const double tau = 1.5e6 * f.optical_depth(o, d);
    if (sig) *sig = f.signature(o, d);
    return Le * (1.0 - std::exp(-tau));
  });
  expect_closed_form(s, exact, "tiny density");
  s.media[0].density_scale = 1.0;
  s.media[0].emission.scale = 1e6;
  s.film.width = s.film.height = 8;
  s.film.spp = 64;
  for (const char* est : kEstimators) {
    s.integrator.emission_estimator = est;
    RenderResult r = render(s);
    for (double v : r.sum) ASSERT_TRUE(std::isfinite(v) && v >= 0.0) << est;
  }
}

// Camera inside the grid (in its constant region, looking across it).
TEST_F(VulkanVdb, CameraInsideTheVolume) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.camera.position = {0.1, 0.05, -0.3};
  s.camera.look_at = {0.3, 0.2, 1.0};
  s.camera.fov_deg = 70.0;
  expect_closed_form(s, test::constant_box_exact(s, field()), "camera inside");
}

// The camera in the plane of a face of the texel support box and of a face of
// the centre box, looking along them: the middle row and column graze.
TEST_F(VulkanVdb, RaysGrazingTheBoundingBoxFaces) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  const Bounds sup = test::support_box(lat, box), cen = test::centre_box(lat, box);
  s.camera.position = {cen.max.x, sup.max.y, -4.0};
  s.camera.look_at = {cen.max.x, sup.max.y, 0.0};
  s.camera.fov_deg = 15.0;
  expect_closed_form(s, test::constant_box_exact(s, field()), "grazing");
}

// Long rays: the camera 1e4 units away (t ≈ 1e4 in float32 on the GPU) with a
// fov that frames the grid.
//
// Regression test for a bug this test found (fixed in render.comp): at t ≈ 1e4
// the position o + t·d lost ~1e-3 units to float cancellation, the DDA's
// minimum step (~2e-4) fell below ulp(1e4), t stopped advancing and the lane
// spun until llvmpipe's loop limiter dropped its samples (a real GPU would
// hang). The origin now moves to the ray's first media/surface entry, and the
// DDA's minimum step is at least 1e-6·t.
TEST_F(VulkanVdb, LongRays) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.camera.position = {0.3, 0.2, -1.0e4};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.fov_deg = 2.0 * std::atan(1.0 / 1.0e4) * 180.0 / 3.14159265358979;
  expect_closed_form(s, test::constant_box_exact(s, field()), "long rays");
}

// A temperature grid on ANOTHER lattice (voxel 0.13, shifted) covering only
// part of the density: emission comes from the temperature THERE (issue 4).
// cpu_vdb_test's design: T = (v − (1 − 1e-4))·6e7 K puts the stored 1.0 at
// 6000 K and everything below v = 0.9999 under cutoff_k, so the hot region is
// the temperature grid's centre box; with max_depth 0 and σa/σt constant,
//   L = Σ_k (σa/σt)·Le·(e^{−σt τ(ta)} − e^{−σt τ(tb)}) + bg·e^{−σt τ}.
TEST_F(VulkanVdb, TemperatureGridOnAnotherLatticeEmitsWhereItIsHot) {
  const test::TemperatureBox tb{{0.13, {0.065, -0.03, 0.02}}, {{-3, -2, -3}, {2, 3, 3}}, 1.0f};
  const Scene s = hot_box_scene("tbox.vdb", tb);
  const Bounds hot = test::centre_box(tb.lattice, tb.box);
  auto exact_for = [&](const Bounds& hot_box) { return hot_box_exact(s, hot_box); };
  RenderResult r = expect_closed_form(s, exact_for(hot), "temperature lattice");
  // The check can fail: the hot box on the DENSITY's lattice (the classic
  // mistake: temperature indices read with the density transform) is rejected.
  const Bounds wrong_hot = test::centre_box(lat, tb.box);
  ZTestReport wrong = test::ztest_against_exact(r, exact_for(wrong_hot), pooled());
  EXPECT_FALSE(wrong.ok) << "temperature on the density's lattice was accepted: " << wrong.summary();
  std::printf("deliberately wrong (density lattice): %s\n", wrong.summary().c_str());
}

// A temperature grid on the density's own lattice (as the Blender 2.79 and
// Mantaflow exports have them) is the density texture's second channel: one
// lookup reads both (docs/rendering.md). Over a box other than the density's (sticking out on
// some sides, short on others) the image is the closed form's, and a hot box
// one voxel off is rejected. Over the same box it is bit-identical to the
// image with the temperature in a texture of its own: the same texel
// coordinates, the same values.
TEST_F(VulkanVdb, TemperatureOnTheDensityLatticeSharesItsTexture) {
  const test::TemperatureBox tb{lat, {{-7, -8, -6}, {7, 5, 9}}, 1.0f};
  const Scene s = hot_box_scene("shared.vdb", tb);
  {  // the layout this test is about
    const StoredVolume v = load_stored_volume(s.media[0]);
    ASSERT_TRUE(v.temperature);
    ASSERT_TRUE(temperature_fits_density_texture(v.density, *v.temperature, ~uint64_t(0)));
  }
  auto exact_for = [&](const Bounds& hot_box) { return hot_box_exact(s, hot_box); };
  const RenderResult r =
      expect_closed_form(s, exact_for(test::centre_box(lat, tb.box)), "temperature in the density texture");
  test::VoxelBox off = tb.box;
  off.lo.x += 1;
  off.hi.x += 1;
  ZTestReport wrong = test::ztest_against_exact(r, exact_for(test::centre_box(lat, off)), pooled());
  EXPECT_FALSE(wrong.ok) << "the hot box one voxel off was accepted: " << wrong.summary();
  std::printf("deliberately wrong (one voxel off): %s\n", wrong.summary().c_str());

  // The same box: bit for bit against a texture of its own, with scattering
  // and the collision estimator (every tentative collision reads the temperature).
  Scene same = hot_box_scene("same.vdb", test::TemperatureBox{lat, box, 1.0f});
  same.film.spp = 64;
  same.integrator.max_depth = 4;
  same.integrator.emission_estimator = "collision";
  RenderSettings apart = settings_for(same);
  apart.temperature_in_density = false;
  const RenderResult shared = render(same), own = backend_->render(same, apart, {});
  ASSERT_EQ(shared.sum.size(), own.sum.size());
  size_t differing = 0;
  double total = 0.0;
  for (size_t i = 0; i < shared.sum.size(); ++i) {
    differing += shared.sum[i] != own.sum[i] || shared.sum_sq[i] != own.sum_sq[i];
    total += shared.sum[i];
  }
  EXPECT_EQ(differing, 0u) << "of " << shared.sum.size() << " channel sums";
  EXPECT_EQ(shared.density_lookups, own.density_lookups);
  EXPECT_GT(total, 0.0);
}

// NaN voxels are 0: a grid with NaN voxels renders bit-identically to the same
// grid with zeros there, and the render reports a warning.
TEST_F(VulkanVdb, NanVoxelsRenderLikeZeros) {
  auto nan_at = [](int i, int j, int k) { return (i * 7 + j * 3 + k) % 5 == 0; };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  test::write_vdb(dir / "nan.vdb", {test::make_float_grid("density", lat, box, [&](int i, int j, int k) {
                    return nan_at(i, j, k) ? nan : 1.0f;
                  })});
  test::write_vdb(dir / "zeros.vdb", {test::make_float_grid("density", lat, box, [&](int i, int j, int k) {
                    return nan_at(i, j, k) ? 0.0f : 1.0f;
                  })});
  Scene a = test::vdb_base_scene(16, 16, 16);
  a.background = {0.1, 0.2, 0.3};
  a.media.push_back(test::vdb_medium("m", dir / "nan.vdb", {1, 2, 3}, {1, 1, 1}, 0.2, glm::dvec3(1, 1, 1)));
  Scene b = a;
  b.media[0].file = dir / "zeros.vdb";
  RenderResult ra = render(a), rb = render(b);
  ASSERT_FALSE(ra.warnings.empty());
  EXPECT_NE(ra.warnings[0].find("NaN"), std::string::npos) << ra.warnings[0];
  EXPECT_EQ(ra.sum, rb.sum);
  EXPECT_EQ(ra.sum_sq, rb.sum_sq);
  EXPECT_EQ(ra.density_lookups, rb.density_lookups);
  EXPECT_GT(ra.density_lookups, 0.0);
}

}  // namespace
}  // namespace pyrolume
