// Hard cases of the lights (docs/robustness.md "Hard cases"): an emission CDF
// whose total is zero (host/light/EmissionCdf), a one-voxel emission CDF, and
// environment maps that are all zero or one bright pixel
// (host/light/EnvironmentMap) — sampled on the host, and rendered on the CPU
// reference and on Vulkan (every render also asserts finite output and
// nonfinite_samples == 0).
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "color/ColorSpace.h"
#include "hardcases/HardCaseFixture.h"
#include "image/ImageIo.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "render/vulkan/LightPacking.h"
#include "scene/MediumVolume.h"
#include "support/SurfaceScenes.h"
#include "volume/StoredVolume.h"

namespace pyrolume {
namespace {

using hard::pooled;
constexpr double kPi = std::numbers::pi;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The u values a sampler must survive: the ends of [0, 1], 1 itself (one past
// what a uniform sampler returns) and NaN.
const double kEdgeU[] = {0.0, 1e-300, 0.5, std::nextafter(1.0, 0.0), 1.0, kNaN};

// ------------------------------------------------------------ emission CDF ----

// Grids with density but no emission anywhere: temperature below the cutoff,
// NaN temperatures (read as 0), emission.scale 0, σa 0, and constant-rgb
// emission on a zero-density grid. The CDF's total is 0: it must be empty,
// every sample must have pdf 0 (and no garbage position), and pdf() must be 0
// everywhere, including NaN and infinite points; the GPU header says 0 entries.
TEST(HardLights, EmissionCdfWithZeroTotalIsSafe) {
  const auto dir = test::temp_dir("hardcases-cdf");
  const test::Lattice lat{0.1, {0.02, -0.01, 0.03}};
  const test::VoxelBox box{{-4, -3, -2}, {4, 3, 2}};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto cold = test::write_constant_box_vdb(dir / "cold.vdb", lat, box, 0.75f, test::TemperatureBox{lat, box, 50.0f});
  const auto nan_t = test::write_constant_box_vdb(dir / "nan.vdb", lat, box, 0.75f, test::TemperatureBox{lat, box, nan});
  const auto zero = test::write_constant_box_vdb(dir / "zero.vdb", lat, box, 0.0f);
  const auto hot = test::write_constant_box_vdb(dir / "hot.vdb", lat, box, 0.75f, test::TemperatureBox{lat, box, 3000.0f});
  struct Case {
    const char* what;
    Medium m;
  };
  std::vector<Case> cases;
  cases.push_back({"temperature below cutoff", test::vdb_medium("m", cold, {1, 1, 1}, {0, 0, 0}, 0.0, std::nullopt, 1.0, true)});
  cases.push_back({"NaN temperatures", test::vdb_medium("m", nan_t, {1, 1, 1}, {0, 0, 0}, 0.0, std::nullopt, 1.0, true)});
  cases.push_back({"emission.scale 0", test::vdb_medium("m", hot, {1, 1, 1}, {0, 0, 0}, 0.0, std::nullopt, 1.0, true)});
  cases.back().m.emission.scale = 0.0;
  cases.push_back({"sigma_a 0", test::vdb_medium("m", hot, {0, 0, 0}, {1, 1, 1}, 0.0, std::nullopt, 1.0, true)});
  cases.push_back({"zero density, rgb", test::vdb_medium("m", zero, {1, 1, 1}, {0, 0, 0}, 0.0, glm::dvec3(2.0))});
  for (const Case& c : cases) {
    const StoredVolume vol = load_stored_volume(c.m);
    const EmissionCdf cdf = EmissionCdf::build(c.m, vol);
    EXPECT_TRUE(cdf.empty()) << c.what;
    EXPECT_EQ(cdf.entry_count(), 0u) << c.what;
    EXPECT_EQ(cdf.power(), 0.0) << c.what;
    EXPECT_TRUE(cdf.cluster_cdf().empty()) << c.what;
    EXPECT_EQ(pack_gpu_emission_header(cdf).entry_count, 0u) << c.what;
    for (double u : kEdgeU)
      for (double u3 : {0.0, 0.5, std::nextafter(1.0, 0.0)}) {
        const EmissionSample s = cdf.sample(u, glm::dvec3(u3));
        EXPECT_EQ(s.pdf, 0.0) << c.what << " u " << u;
        EXPECT_TRUE(finite3(s.p)) << c.what << " u " << u;
      }
    for (const glm::dvec3& p : {lat.world(glm::dvec3(0.0)), lat.world(glm::dvec3(100.0)), glm::dvec3(kNaN),
                                glm::dvec3(std::numeric_limits<double>::infinity())})
      EXPECT_EQ(cdf.pdf(p), 0.0) << c.what;
  }
  // The hot grid does emit (the cases above are empty for their reason, not
  // because building always fails).
  const Medium m = test::vdb_medium("m", hot, {1, 1, 1}, {0, 0, 0}, 0.0, std::nullopt, 1.0, true);
  EXPECT_FALSE(EmissionCdf::build(m, load_stored_volume(m)).empty());
  std::filesystem::remove_all(dir);
}

// A one-voxel grid with constant emission: 3³ texels, 2³ cells, all with the
// voxel as a corner, so all 8 have the same weight. Samples land inside the
// support, pdf(sample) equals the sampled pdf = 1/(8 · cell volume), and the
// edge values of u stay inside the distribution.
TEST(HardLights, EmissionCdfOfOneVoxel) {
  const auto dir = test::temp_dir("hardcases-cdf1");
  const test::Lattice lat{0.5, {0.1, 0.2, -0.3}};
  const test::VoxelBox one{{0, 0, 0}, {0, 0, 0}};
  const Medium m = test::vdb_medium("one", test::write_constant_box_vdb(dir / "one.vdb", lat, one, 2.0f), {1, 2, 3},
                                    {0, 0, 0}, 0.0, glm::dvec3(1.0, 0.5, 0.25));
  const EmissionCdf cdf = EmissionCdf::build(m, load_stored_volume(m));
  ASSERT_FALSE(cdf.empty());
  EXPECT_EQ(cdf.cells(), glm::ivec3(2));
  EXPECT_EQ(cdf.entry_count(), 8u);
  const double expected_pdf = 1.0 / (8.0 * std::pow(lat.voxel, 3));
  const Bounds sup = test::support_box(lat, one);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<int> hits(8, 0);
  for (int k = 0; k < 8000; ++k) {
    const double u = k < 6 ? (kEdgeU[k] == kEdgeU[k] ? kEdgeU[k] : 0.25) : U(rng);  // NaN is not a valid u here
    const EmissionSample s = cdf.sample(u, {U(rng), U(rng), U(rng)});
    ASSERT_NEAR(s.pdf, expected_pdf, 1e-6 * expected_pdf) << "u " << u;
    ASSERT_NEAR(cdf.pdf(s.p), s.pdf, 1e-9 * s.pdf);
    for (int a = 0; a < 3; ++a) ASSERT_TRUE(s.p[a] >= sup.min[a] - 1e-12 && s.p[a] <= sup.max[a] + 1e-12);
    ++hits[s.cell];
  }
  std::vector<double> obs(hits.begin(), hits.end()), exp(8, 8000.0 / 8.0);
  const test::ChiSquareResult chi = test::chi_square(obs, exp);
  EXPECT_GT(chi.p_value, 1e-4) << chi.summary();
  std::filesystem::remove_all(dir);
}

// --------------------------------------------------------- environment map ----

Image one_bright_pixel(int w, int h, int i, int j, glm::vec3 value) {
  Image img = make_image(w, h);
  for (int c = 0; c < 3; ++c) img.at(i, j, c) = value[c];
  return img;
}

// An all-zero map has no distribution: every sample has pdf 0, pdf() and the
// radiance are 0 in every direction (the poles and the seam included).
TEST(HardLights, EnvironmentMapAllZeroIsSafe) {
  const EnvironmentMap env = EnvironmentMap::from_image(make_image(16, 8), 3.0, 30.0);
  EXPECT_FALSE(env.has_distribution());
  EXPECT_EQ(env.power(), 0.0);
  EXPECT_EQ(pack_gpu_environment_header(env).can_sample, 0u);
  for (double u : kEdgeU)
    for (double v : kEdgeU) {
      const EnvSample s = env.sample({u, v});
      EXPECT_EQ(s.pdf, 0.0);
      EXPECT_EQ(s.radiance, glm::dvec3(0.0));
    }
  for (const glm::dvec3& d : {glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1), glm::dvec3(-1, 0, 0), glm::dvec3(0.3, -0.2, 0.9)}) {
    EXPECT_EQ(env.pdf(d), 0.0);
    EXPECT_EQ(env.radiance(d), glm::dvec3(0.0));
  }
}

// One bright texel, inside the map and at its corner (top row: the pole; first
// column: the seam). Every sample is finite with pdf > 0, pdf(dir) equals the
// sampled pdf, the sampled radiance is the lookup; and importance sampling is
// unbiased: the mean of radiance/pdf matches ∫ radiance dω from a fine (u, v)
// quadrature (dω = 2π² sinθ du dv) within 4 standard errors, with an SE small
// enough (< 1 %) to tell.
TEST(HardLights, EnvironmentMapOneBrightPixel) {
  for (const glm::ivec2 texel : {glm::ivec2(5, 2), glm::ivec2(0, 0)}) {
    const EnvironmentMap env = EnvironmentMap::from_image(one_bright_pixel(16, 8, texel.x, texel.y, {50, 40, 30}), 2.0, 10.0);
    ASSERT_TRUE(env.has_distribution());
    glm::dvec3 quad(0.0);
    const int NU = 1024, NV = 512;
    for (int b = 0; b < NV; ++b)
      for (int a = 0; a < NU; ++a) {
        const glm::dvec2 uv((a + 0.5) / NU, (b + 0.5) / NV);
        quad += env.scale() * env.lookup_uv(uv) * (2.0 * kPi * kPi * std::sin(kPi * uv.y)) / double(NU * NV);
      }
    std::mt19937_64 rng(11 + texel.x);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const int N = 100000;
    glm::dvec3 sum(0.0), sum_sq(0.0);
    for (int k = 0; k < N; ++k) {
      const EnvSample s = env.sample({U(rng), U(rng)});
      ASSERT_TRUE(s.pdf > 0.0 && std::isfinite(s.pdf)) << "texel " << texel.x << "," << texel.y << " sample " << k;
      ASSERT_TRUE(finite3(s.dir) && finite3(s.radiance));
      ASSERT_NEAR(env.pdf(s.dir), s.pdf, 1e-6 * s.pdf);
      const glm::dvec3 L = env.radiance(s.dir);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(L[c], s.radiance[c], 1e-9 * (1.0 + L[c]));
      const glm::dvec3 f = s.radiance / s.pdf;
      sum += f;
      sum_sq += f * f;
    }
    for (int c = 0; c < 3; ++c) {
      const double mean = sum[c] / N, se = std::sqrt((sum_sq[c] / N - mean * mean) / (N - 1));
      EXPECT_LT(se, 0.01 * quad[c]);
      EXPECT_LT(std::abs(mean - quad[c]), 4.0 * se)
          << "texel " << texel.x << "," << texel.y << " channel " << c << ": " << mean << " vs " << quad[c] << " ± " << se;
      std::printf("bright texel (%d, %d) channel %d: E[L/pdf] %.5g ± %.2g, quadrature %.5g\n", texel.x, texel.y, c, mean,
                  se, quad[c]);
    }
  }
}

// ------------------------------------------------- rendering with them ----

template <class B>
class HardLightRender : public hard::HardCase<B> {};
TYPED_TEST_SUITE(HardLightRender, hard::Backends, hard::BackendNames);

// A grid that emits nothing (cold, and NaN temperatures in half of it): its
// emission CDF is empty (above), and the render is the absorbing closed form
// L = bg · e^{−σa τ}.
TYPED_TEST(HardLightRender, GridWithZeroEmissionTotal) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  test::write_vdb(this->dir / "cold.vdb",
                  {test::make_float_grid("density", this->lat, this->box, [&](int, int, int) { return this->c; }),
                   test::make_float_grid("temperature", this->lat, this->box,
                                         [nan](int i, int, int) { return i < 0 ? nan : 50.0f; })});
  Scene s = this->constant_box_scene(16, 16, 256, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.media[0] = test::vdb_medium("cold", this->dir / "cold.vdb", {0.8, 1.6, 3.2}, {0, 0, 0}, 0.0, std::nullopt, 1.0, true);
  s.media[0].density_scale = 1.5;
  s.background = {0.5, 0.8, 1.0};
  this->expect_closed_form(s, test::constant_box_exact(s, this->field()), "zero emission total", pooled(0.01));
}

// An all-zero environment map (the background colour, 7, must not show):
// with a σs-only sphere nothing emits, so every sample is exactly 0; with an
// emissive, scattering sphere the image equals the same scene under a black
// background (another seed, z-test).
TYPED_TEST(HardLightRender, AllZeroEnvironmentMap) {
  const auto exr = this->dir / "black.exr";
  write_image(exr, make_image(16, 8));
  Scene furnace = test::white_furnace_scene(16, 16, 16);
  furnace.background = glm::dvec3(7.0);
  furnace.environment = Environment{exr, 1.0, 0.0};
  for (const EmissionEstimator est : hard::kEstimators) {
    furnace.integrator.emission_estimator = est;
    const RenderResult r = this->render(furnace, to_string(est));
    this->expect_every_pixel(r, glm::dvec3(0.0), "zero map furnace");
  }
  Scene glow = test::chromatic_scattering_scene(16, 16, 1024);
  glow.background = glm::dvec3(7.0);
  glow.environment = Environment{exr, 1.0, 0.0};
  Scene black = glow;
  black.environment.reset();
  black.background = glm::dvec3(0.0);
  black.film.seed = 1234;
  const test::ZTestReport rep = test::ztest_images(this->render(glow, "zero map"), this->render(black, "black"), pooled(0.01));
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("zero map vs black background: %s\n", rep.summary().c_str());
}

// One bright texel. Camera rays straight to the map (fov 100°, +Z up, the
// background 7 must not show): the exact image is EnvironmentMap::radiance
// pixel-averaged, for the texel inside the map and for the corner texel seen
// around the pole. Then a σs-only sphere lit by the inside texel (48° off the view axis, behind the sphere, out of
// the view: Vulkan against the CPU reference (a spike seen through
// scattering, sampled by the phase function alone: tolerance 5 %).
TYPED_TEST(HardLightRender, OneBrightPixelEnvironmentMap) {
  // The spike varies strongly inside a pixel: 1024 jittered samples; around
  // the pole most pixels are black and a few very bright, so 2 % there.
  struct View {
    glm::ivec2 texel;
    glm::dvec3 look, up;
    double tolerance;
  };
  for (const View& v : {View{{5, 2}, {0, 0, 0}, {0, 0, 1}, 0.01}, View{{0, 0}, {0, 0, 1}, {1, 0, 0}, 0.02}}) {
    const auto exr = this->dir / ("bright" + std::to_string(v.texel.x) + ".exr");
    write_image(exr, one_bright_pixel(16, 8, v.texel.x, v.texel.y, {50, 40, 30}));
    const EnvironmentMap env = EnvironmentMap::load(exr, 2.0, 10.0);
    Scene s = test::analytic_base_scene(16, 16, 1024);
    s.camera.position = {0, 0, 0};
    s.camera.look_at = v.texel == glm::ivec2(0, 0) ? v.look : env.uv_to_direction({(v.texel.x + 0.5) / 16.0, (v.texel.y + 0.5) / 8.0});
    s.camera.up = v.up;
    s.camera.fov_deg = 100.0;
    s.background = glm::dvec3(7.0);
    s.environment = Environment{exr, 2.0, 10.0};
    const RenderResult r = this->render(s, "direct view");
    auto exact = test::exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
      const glm::dvec3 d = test::film_ray(s.camera, s.film.width, s.film.height, fx, fy);
      const glm::dvec2 uv = env.direction_to_uv(d);
      *sig = int(std::floor(uv.x * env.width() - 0.5)) * 1000 + int(std::floor(uv.y * env.height() - 0.5));
      return env.radiance(d);
    });
    const test::ZTestReport rep = test::ztest_against_exact(r, exact, pooled(v.tolerance));
    EXPECT_TRUE(rep.ok) << "texel " << v.texel.x << "," << v.texel.y << ": " << rep.summary();
    std::printf("bright texel (%d, %d) direct view: %s\n", v.texel.x, v.texel.y, rep.summary().c_str());
  }

  const auto exr = this->dir / "bright5.exr";
  Scene s = test::analytic_base_scene(16, 16, 1024);
  s.camera.position = {0.0, -4.0, 0.3};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.up = {0, 0, 1};
  s.background = glm::dvec3(7.0);
  s.environment = Environment{exr, 2.0, 10.0};
  s.integrator.max_depth = 64;
  s.media.push_back(test::homogeneous_sphere("cloud", {0, 0, 0}, 1.2, {0, 0, 0}, {1.0, 1.5, 2.0}, 0.0, std::nullopt));
  const RenderResult r = this->render(s, "lit cloud");
  if constexpr (TestFixture::kVulkan) {
    const RenderResult ref = this->cpu_reference(s, 1024, 4321);
    const test::ZTestReport rep = test::ztest_images(r, ref, pooled(0.05));
    EXPECT_TRUE(rep.ok) << rep.summary();
    std::printf("lit cloud vs CPU: %s\n", rep.summary().c_str());
  }
}

}  // namespace
}  // namespace pyrolume
