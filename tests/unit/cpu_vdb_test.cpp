// CPU reference with grid (vdb) media: the cases both backends share run from
// tests/support/VdbSuite.h (Vdb.*/"cpu"); here, the CPU-only ones (estimators
// against each other on scattering scenes, a white furnace at 1e-12, the NaN
// warning of the prepared media, the 5 nm blackbody sum). Every VDB is written
// by the test (tests/support/VdbScenes.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <gtest/gtest.h>

#include "color/Blackbody.h"
#include "render/cpu/CpuRenderer.h"
#include "render/cpu/Media.h"
#include "scene/MediumVolume.h"
#include "support/Stats.h"
#include "support/VdbSuite.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Vdb, "cpu");
}  // namespace test

namespace {

using test::kVdbEstimators;
using test::pooled;
using test::ZTestReport;

class CpuVdb : public test::VdbFixture {
 protected:
  CpuVdb() : test::VdbFixture("cpu") {}
};

// No closed form with multiple scattering: the two estimators must converge to
// the same image. A sparse explosion shell (scattering, absorbing, emitting rgb)
// overlapping a homogeneous emissive sphere.
TEST_F(CpuVdb, AbsorptionAndCollisionEstimatorsAgreeWithScattering) {
  const test::Lattice shell_lat{0.07, {0.0, 0.0, 0.0}};
  Scene s = shell_view(24, 24, 512, {0.1, 0.15, 0.3}, 8);
  s.media.push_back(test::vdb_medium("shell", test::write_explosion_shell_vdb(dir / "shell.vdb", shell_lat),
                                     {1.0, 1.5, 2.0}, {2.0, 1.5, 1.0}, 0.5, glm::dvec3(1.5, 0.7, 0.2), 1.0));
  s.media[0].density_scale = 2.0;
  s.media.push_back(test::homogeneous_sphere("core", {0.1, 0.0, 0.0}, 0.5, {0.5, 0.5, 0.5}, {0.5, 0.3, 0.1}, -0.3,
                                             glm::dvec3(0.2, 0.5, 1.0)));
  RenderResult r[2];
  for (int i = 0; i < 2; ++i) {
    s.integrator.emission_estimator = kVdbEstimators[i];
    r[i] = render(s);
    std::printf("%s: %.2f s, lookups/sample %.2f, events/sample %.3f\n", to_string(kVdbEstimators[i]), r[i].seconds,
                r[i].density_lookups / (24.0 * 24 * 512), r[i].events / (24.0 * 24 * 512));
  }
  ZTestReport rep = test::ztest_images(r[1], r[0], pooled(0.01));
  EXPECT_TRUE(rep.ok) << rep.summary();
  std::printf("collision vs absorption: %s\n", rep.summary().c_str());
}

// The same with blackbody emission from the shell's temperature grid (smaller:
// the collision estimator evaluates Planck at every tentative collision).
TEST_F(CpuVdb, EstimatorsAgreeWithTemperatureEmission) {
  const test::Lattice shell_lat{0.07, {0.0, 0.0, 0.0}};
  Scene s = shell_view(16, 16, 256, {0.1, 0.1, 0.1}, 4);
  s.media.push_back(test::vdb_medium("shell", test::write_explosion_shell_vdb(dir / "shell.vdb", shell_lat),
                                     {1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}, 0.3, std::nullopt, 2.0, true));
  s.media[0].emission.blackbody = BlackbodyMode::Seed;
  s.media[0].temperature.cutoff_k = 800.0;
  RenderResult r[2];
  for (int i = 0; i < 2; ++i) {
    s.integrator.emission_estimator = kVdbEstimators[i];
    r[i] = render(s);
    std::printf("%s: %.2f s\n", to_string(kVdbEstimators[i]), r[i].seconds);
  }
  ZTestReport rep = test::ztest_images(r[1], r[0], pooled(0.02));
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
  for (const EmissionEstimator est : kVdbEstimators) {
    s.integrator.emission_estimator = est;
    RenderResult r = render(s);
    for (size_t i = 0; i < r.sum.size(); ++i)
      ASSERT_NEAR(r.sum[i] / r.spp, s.background[i % 3], 1e-12 * s.background[i % 3]) << to_string(est) << " at " << i;
    EXPECT_GT(r.events, 0.0);
  }
}

// NaN voxels are 0 in the CPU's prepared media (the loader warns, and the
// largest density ignores them); Vdb.NanVoxelsRenderLikeZeros/"cpu" renders them.
TEST_F(CpuVdb, NanVoxelsAreZero) {
  const auto [a, b] = nan_and_zero_scenes();
  const cpu::MediaData md = cpu::prepare_media(a);
  ASSERT_FALSE(md.warnings.empty());
  EXPECT_NE(md.warnings[0].find("NaN"), std::string::npos) << md.warnings[0];
  EXPECT_EQ(md.media[0].max_density, 1.0);
  EXPECT_EQ(cpu::prepare_media(b).media[0].max_density, 1.0);
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
