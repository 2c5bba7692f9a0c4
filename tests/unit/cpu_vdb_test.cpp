// CPU reference with grid (vdb) media: delta tracking with a global majorant,
// both emission estimators, against closed forms (issue 5 parts 2 and 5, and
// its hard cases). Every VDB is written by the test (tests/support/VdbScenes.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/packing.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "color/Blackbody.h"
#include "render/cpu/CpuRenderer.h"
#include "render/cpu/Intersect.h"
#include "render/cpu/Media.h"
#include "scene/MediumVolume.h"
#include "support/AnalyticScenes.h"
#include "support/Stats.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

using test::ZTestOptions;
using test::ZTestReport;

RenderResult render(const Scene& s, uint64_t* violations = nullptr) {
  RenderSettings rs;
  rs.width = s.film.width;
  rs.height = s.film.height;
  rs.spp = s.film.spp;
  rs.seed = s.film.seed;
  CpuRenderer r;
  RenderResult res = r.render(s, rs, {});
  EXPECT_EQ(r.majorant_violations(), 0u) << "sigma_t exceeded the majorant";
  EXPECT_EQ(res.nonfinite_samples, 0u);
  if (violations) *violations = r.majorant_violations();
  return res;
}

// Absorption-estimator samples are Bernoulli-like (Le or background): pool the
// variance over 3×3 (Stats.h explains).
ZTestOptions pooled() {
  ZTestOptions o;
  o.pool3x3 = true;
  return o;
}

const char* kEstimators[] = {"absorption", "collision"};

// The constant box (lat, box, c, dir, constant_box_scene, field) comes from
// test::ConstantBoxSetup, shared with vulkan_vdb_test.
class CpuVdb : public ::testing::Test, public test::ConstantBoxSetup {
 protected:
  CpuVdb() : test::ConstantBoxSetup("cpu_vdb") {}

  void expect_closed_form(Scene s, const test::ConstantBoxField& f, const char* what) {
    auto exact = test::constant_box_exact(s, f);
    for (const char* est : kEstimators) {
      s.integrator.emission_estimator = est;
      RenderResult r = render(s);
      ZTestReport rep = test::ztest_against_exact(r, exact, pooled());
      EXPECT_TRUE(rep.ok) << what << " [" << est << "] " << rep.summary();
      std::printf("%s [%s]: %s; lookups/sample %.2f, events/sample %.3f, %.2f s\n", what, est, rep.summary().c_str(),
                  r.density_lookups / (double(r.width) * r.height * r.spp),
                  r.events / (double(r.width) * r.height * r.spp), r.seconds);
      EXPECT_LE(r.events, r.density_lookups) << "a real collision without a density lookup";
    }
  }
};

// A constant grid is the homogeneous medium of the same density, except within
// one voxel of its edge, where the texture blends with its zero padding. A
// homogeneous box compared image-to-image would differ there, so instead the
// grid is compared with the exact closed form of the field it really is
// (ConstantBoxField: the constant in the centre box, a separable linear ramp to 0
// around it; its optical depth integrated exactly), seen obliquely so that
// faces, edges and corners of the ramp are all in view. With σs = 0,
// L = Le(1 − e^{−σa τ}) + bg·e^{−σa τ}: the homogeneous medium's closed form with
// the chord replaced by ∫ρ. The test fails for a wrong density_scale, a
// half-voxel shift of the texels, a transposed axis or clipping to the wrong box.
TEST_F(CpuVdb, ConstantGridMatchesClosedFormIncludingEdgeRamp) {
  Scene s = constant_box_scene(32, 32, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  expect_closed_form(s, field(), "constant grid");
}

// Same with scattering as pure extinction (max_depth 0): L = (σa/σt)·Le·(1 − e^{−σt τ}) + bg·e^{−σt τ}.
TEST_F(CpuVdb, ScatteringGridAtMaxDepthZeroIsExtinction) {
  Scene s = constant_box_scene(24, 24, 512, {0.5, 0.3, 0.2}, {0.6, 1.2, 2.0});
  s.integrator.max_depth = 0;
  expect_closed_form(s, field(), "max_depth 0");
}

// The whole scene (grid and camera) rotated and moved by the medium transform
// gives the unrotated closed form: rays are clipped to the ORIENTED texel box.
TEST_F(CpuVdb, RotatedGridMatchesUnrotatedClosedForm) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  auto exact = test::constant_box_exact(s, field());
  s.media[0].transform.rotate_deg = {20.0, 35.0, -15.0};
  s.media[0].transform.translate = {0.4, -0.3, 0.2};
  const glm::dmat4 M = medium_transform_matrix(s.media[0].transform);
  s.camera.position = glm::dvec3(M * glm::dvec4(s.camera.position, 1.0));
  s.camera.look_at = glm::dvec3(M * glm::dvec4(s.camera.look_at, 1.0));
  s.camera.up = glm::dvec3(M * glm::dvec4(s.camera.up, 0.0));
  RenderResult r = render(s);
  ZTestReport rep = test::ztest_against_exact(r, exact, pooled());
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("rotated: %s\n", rep.summary().c_str());
}

// No closed form with multiple scattering: the two estimators must converge to
// the same image. A sparse explosion shell (scattering, absorbing, emitting rgb)
// overlapping a homogeneous emissive sphere.
TEST_F(CpuVdb, AbsorptionAndCollisionEstimatorsAgreeWithScattering) {
  const test::Lattice shell_lat{0.07, {0.0, 0.0, 0.0}};
  Scene s = test::vdb_base_scene(24, 24, 512);
  s.camera.position = {0.3, 0.4, -3.5};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.background = {0.1, 0.15, 0.3};
  s.integrator.max_depth = 8;
  s.media.push_back(test::vdb_medium("shell", test::write_explosion_shell_vdb(dir / "shell.vdb", shell_lat),
                                     {1.0, 1.5, 2.0}, {2.0, 1.5, 1.0}, 0.5, glm::dvec3(1.5, 0.7, 0.2), 1.0));
  s.media[0].density_scale = 2.0;
  s.media.push_back(test::homogeneous_sphere("core", {0.1, 0.0, 0.0}, 0.5, {0.5, 0.5, 0.5}, {0.5, 0.3, 0.1}, -0.3,
                                             glm::dvec3(0.2, 0.5, 1.0)));
  RenderResult r[2];
  for (int i = 0; i < 2; ++i) {
    s.integrator.emission_estimator = kEstimators[i];
    r[i] = render(s);
    std::printf("%s: %.2f s, lookups/sample %.2f, events/sample %.3f\n", kEstimators[i], r[i].seconds,
                r[i].density_lookups / (24.0 * 24 * 512), r[i].events / (24.0 * 24 * 512));
  }
  ZTestOptions o = pooled();
  o.bias_tolerance = 0.01;
  ZTestReport rep = test::ztest_images(r[1], r[0], o);
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("collision vs absorption: %s\n", rep.summary().c_str());
}

// The same with blackbody emission from the shell's temperature grid (smaller:
// the collision estimator evaluates Planck at every tentative collision).
TEST_F(CpuVdb, EstimatorsAgreeWithTemperatureEmission) {
  const test::Lattice shell_lat{0.07, {0.0, 0.0, 0.0}};
  Scene s = test::vdb_base_scene(16, 16, 256);
  s.camera.position = {0.3, 0.4, -3.5};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.background = {0.1, 0.1, 0.1};
  s.integrator.max_depth = 4;
  s.media.push_back(test::vdb_medium("shell", test::write_explosion_shell_vdb(dir / "shell.vdb", shell_lat),
                                     {1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}, 0.3, std::nullopt, 2.0, true));
  s.media[0].emission.blackbody = BlackbodyMode::Seed;
  s.media[0].temperature.cutoff_k = 800.0;
  RenderResult r[2];
  for (int i = 0; i < 2; ++i) {
    s.integrator.emission_estimator = kEstimators[i];
    r[i] = render(s);
    std::printf("%s: %.2f s\n", kEstimators[i], r[i].seconds);
  }
  ZTestOptions o = pooled();
  o.bias_tolerance = 0.02;
  ZTestReport rep = test::ztest_images(r[1], r[0], o);
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("collision vs absorption (blackbody): %s\n", rep.summary().c_str());
}

// White furnace with a heterogeneous scattering grid (σa = 0, checkerboard
// density, anisotropic HG): every path escapes with the background, so every
// sample is exactly the background; null collisions and scattering must lose
// no energy.
TEST_F(CpuVdb, ScatteringCheckerboardWhiteFurnace) {
  Scene s = test::vdb_base_scene(16, 16, 32);
  s.background = {0.3, 0.6, 0.9};
  s.integrator.max_depth = 100000;
  s.media.push_back(test::vdb_medium(
      "checker", test::write_checkerboard_vdb(dir / "checker.vdb", lat, box, 0.25f, 2.0f, 2), {0, 0, 0},
      {0.5, 1.0, 2.0}, 0.6));
  for (const char* est : kEstimators) {
    s.integrator.emission_estimator = est;
    RenderResult r = render(s);
    for (size_t i = 0; i < r.sum.size(); ++i)
      ASSERT_NEAR(r.sum[i] / r.spp, s.background[i % 3], 1e-12 * s.background[i % 3]) << est << " at " << i;
    EXPECT_GT(r.events, 0.0);
  }
}

// An all-zero grid and a grid with no active voxels render the background
// exactly and read no texel (the majorant is 0: the medium is skipped).
TEST_F(CpuVdb, ZeroAndEmptyGridsRenderTheBackground) {
  Scene s = test::vdb_base_scene(16, 16, 8);
  s.background = {0.2, 0.4, 0.6};
  s.media.push_back(test::vdb_medium("zero", test::write_constant_box_vdb(dir / "zero.vdb", lat, box, 0.0f),
                                     {1, 1, 1}, {1, 1, 1}, 0.0, glm::dvec3(1.0)));
  s.media.push_back(
      test::vdb_medium("empty", test::write_empty_vdb(dir / "empty.vdb"), {1, 1, 1}, {1, 1, 1}, 0.0, glm::dvec3(1.0)));
  for (const char* est : kEstimators) {
    s.integrator.emission_estimator = est;
    RenderResult r = render(s);
    for (size_t i = 0; i < r.sum.size(); ++i) ASSERT_DOUBLE_EQ(r.sum[i], r.spp * s.background[i % 3]) << est;
    EXPECT_EQ(r.density_lookups, 0.0);
    EXPECT_EQ(r.events, 0.0);
  }
}

// Optical depth 1e4 per voxel: the background is blocked completely and every
// ray through the grid sees exactly Le (its samples have zero variance, so the
// z-test holds those pixels to 1e-6 relative). The closed form covers the
// silhouette, where the edge ramp matters.
TEST_F(CpuVdb, OpticalDepth1e4PerVoxelIsOpaque) {
  Scene s = constant_box_scene(20, 20, 64, {1e5 / 1.5 / 0.75, 1e5 / 1.5 / 0.75, 1e5 / 1.5 / 0.75}, {0, 0, 0});
  s.background = {3.0, 2.0, 1.0};
  expect_closed_form(s, field(), "opaque");
}

// A density of 1e-6 (stored as a half subnormal) with a hot temperature grid
// that covers the whole density texture, so T = 8000 K wherever ρ > 0 and
// L = (σa/σt)·Le(8000 K)·(1 − e^{−σt τ}) + bg·e^{−σt τ} with the STORED density.
// density_scale makes it optically visible, so the test can resolve a bias.
TEST_F(CpuVdb, TinyDensityWithHighTemperature) {
  const float rho = glm::unpackHalf1x16(glm::packHalf1x16(1e-6f));
  ASSERT_GT(rho, 0.0f);
  const test::TemperatureBox tb{{0.15, {0.01, 0.02, -0.03}}, {{-8, -6, -7}, {8, 6, 7}}, 8000.0f};
  Scene s = test::vdb_base_scene(24, 24, 192);
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
  for (const char* est : kEstimators) {
    s.integrator.emission_estimator = est;
    RenderResult r = render(s);
    ZTestReport rep = test::ztest_against_exact(r, exact, pooled());
    EXPECT_TRUE(rep.ok) << est << ": " << rep.summary();
    std::printf("tiny density [%s]: %s; %.2f s\n", est, rep.summary().c_str(), r.seconds);
  }
  // Without the density_scale the medium is nearly transparent (σ̄ ~ 1e-6) while
  // Le is huge: no informative test at affordable spp, but it must stay finite.
  s.media[0].density_scale = 1.0;
  s.media[0].emission.scale = 1e6;
  s.film.width = s.film.height = 8;
  s.film.spp = 64;
  RenderResult r = render(s);
  for (double v : r.sum) ASSERT_TRUE(std::isfinite(v) && v >= 0.0);
}

// Camera inside the grid (in its constant region, looking across it).
TEST_F(CpuVdb, CameraInsideTheVolume) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.camera.position = {0.1, 0.05, -0.3};
  s.camera.look_at = {0.3, 0.2, 1.0};
  s.camera.fov_deg = 70.0;
  expect_closed_form(s, field(), "camera inside");
}

// The camera in the plane of a face of the texel support box (y = top padding
// centres) and of a face of the centre box (x = last active centre), looking
// along them: the middle row and column graze the faces.
TEST_F(CpuVdb, RaysGrazingTheBoundingBoxFaces) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  const Bounds sup = test::support_box(lat, box), cen = test::centre_box(lat, box);
  s.camera.position = {cen.max.x, sup.max.y, -4.0};
  s.camera.look_at = {cen.max.x, sup.max.y, 0.0};
  s.camera.fov_deg = 15.0;
  expect_closed_form(s, field(), "grazing");
}

// Long rays: the camera 1e4 units away with a fov that frames the grid.
TEST_F(CpuVdb, LongRays) {
  Scene s = constant_box_scene(24, 24, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.camera.position = {0.3, 0.2, -1.0e4};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.fov_deg = 2.0 * std::atan(1.0 / 1.0e4) * 180.0 / 3.14159265358979;
  expect_closed_form(s, field(), "long rays");
}

// A temperature grid on ANOTHER lattice (voxel 0.13, shifted) that covers only
// part of the density: emission must come from the temperature THERE, which
// emits only on its centre box (test::ConstantBoxSetup::hot_box_scene).
TEST_F(CpuVdb, TemperatureGridOnAnotherLatticeEmitsWhereItIsHot) {
  const test::TemperatureBox tb{{0.13, {0.065, -0.03, 0.02}}, {{-3, -2, -3}, {2, 3, 3}}, 1.0f};
  Scene s = hot_box_scene("tbox.vdb", tb);
  const auto exact = hot_box_exact(s, test::centre_box(tb.lattice, tb.box));
  for (const char* est : kEstimators) {
    s.integrator.emission_estimator = est;
    RenderResult r = render(s);
    ZTestReport rep = test::ztest_against_exact(r, exact, pooled());
    EXPECT_TRUE(rep.ok) << est << ": " << rep.summary();
    std::printf("temperature lattice [%s]: %s; %.2f s\n", est, rep.summary().c_str(), r.seconds);
  }
}

// NaN voxels are 0: a grid with NaN voxels renders bit-identically to the same
// grid with zeros there (and the loader warns).
TEST_F(CpuVdb, NanVoxelsAreZero) {
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
  const cpu::MediaData md = cpu::prepare_media(a);
  ASSERT_FALSE(md.warnings.empty());
  EXPECT_NE(md.warnings[0].find("NaN"), std::string::npos) << md.warnings[0];
  EXPECT_EQ(md.media[0].max_density, 1.0);
  RenderResult ra = render(a), rb = render(b);
  EXPECT_EQ(ra.sum, rb.sum);
  EXPECT_EQ(ra.density_lookups, rb.density_lookups);
}

// blackbody_rgb_5nm (what the reference evaluates per collision) against the
// 1 nm sum: within 1e-3 of the largest channel, 500 K – 40 000 K, every mode
// and observer, with and without adaptation.
TEST(CpuBlackbody, FiveNanometreSumMatchesOneNanometreSum) {
  double worst = 0.0;
  for (BlackbodyMode mode : {BlackbodyMode::Seed, BlackbodyMode::Peak, BlackbodyMode::Physical})
    for (int observer : {2, 10})
      for (std::optional<double> adapt : {std::optional<double>{}, std::optional<double>{4000.0}})
        for (double T = 500.0; T <= 40000.0 * 1.0001; T *= 1.07) {
          const glm::dvec3 a = color::blackbody_rgb(T, mode, observer, adapt);
          const glm::dvec3 b = color::blackbody_rgb_5nm(T, mode, observer, adapt);
          const double m = std::max({a.r, a.g, a.b});
          ASSERT_GT(m, 0.0);
          for (int k = 0; k < 3; ++k) {
            worst = std::max(worst, std::abs(b[k] - a[k]) / m);
            ASSERT_LE(std::abs(b[k] - a[k]), 1e-3 * m) << "T " << T << " mode " << int(mode) << " obs " << observer;
          }
        }
  std::printf("worst |5 nm − 1 nm| / max channel: %.3g\n", worst);
  EXPECT_EQ(color::blackbody_rgb_5nm(0.0, BlackbodyMode::Peak), glm::dvec3(0.0));
  EXPECT_EQ(color::blackbody_rgb_5nm(std::nan(""), BlackbodyMode::Seed), glm::dvec3(0.0));
}

// The LUT's range: no emission below 100 K (or at/below cutoff_k), clamped at 1e6 K.
TEST(CpuBlackbody, TemperatureRangeMatchesTheGpuLut) {
  cpu::MediumData m;
  m.type = Medium::Type::Vdb;
  m.emission.scale = 2.0;
  m.emission.blackbody = BlackbodyMode::Peak;
  m.temperature.cutoff_k = 50.0;
  EXPECT_EQ(cpu::grid_Le_of_temperature(m, 99.0), glm::dvec3(0.0));
  EXPECT_EQ(cpu::grid_Le_of_temperature(m, std::nan("")), glm::dvec3(0.0));
  EXPECT_GT(cpu::grid_Le_of_temperature(m, 1000.0).r, 0.0);
  EXPECT_EQ(cpu::grid_Le_of_temperature(m, 5e6), cpu::grid_Le_of_temperature(m, 1e6));
  m.temperature.cutoff_k = 1000.0;
  EXPECT_EQ(cpu::grid_Le_of_temperature(m, 1000.0), glm::dvec3(0.0));
  EXPECT_GT(cpu::grid_Le_of_temperature(m, 1001.0).r, 0.0);
}

}  // namespace
}  // namespace pyrolume
