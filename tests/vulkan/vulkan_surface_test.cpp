// The Vulkan backend with surfaces and the environment map (issue 6, BSDF and
// phase sampling only), validation layers on (any message fails). The cases
// both backends share run from tests/support/SurfaceSuite.h
// (Surface.*/"vulkan"); here, the GPU-only ones:
//  - every byte through the R8G8B8A8_SRGB sampler against the IEC curve;
//  - GPU vs the CPU reference (z-tests with the bias formula of docs/testing.md) on a
//    small terrain_explosion and on an emissive scattering medium above a
//    textured plane under an environment map (there with two perturbed
//    references that must be rejected).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "render/cpu/CpuRenderer.h"
#include "scene/Scene.h"
#include "support/Stats.h"
#include "support/SurfaceSuite.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Surface, "vulkan");
}  // namespace test

namespace {

using test::ZTestOptions;
using test::ZTestReport;

using test::pixel_mean;
using test::pooled;

using test::kSrgbDecodeAllowance;

class VulkanSurface : public test::SurfaceFixture {
 protected:
  VulkanSurface() : test::SurfaceFixture("vulkan") {}

  static RenderResult render_cpu(const Scene& s) {
    CpuRenderer cpu;
    RenderResult r = cpu.render(s, test::settings_for(s), {});
    EXPECT_EQ(cpu.majorant_violations(), 0u);
    EXPECT_EQ(r.nonfinite_samples, 0u);
    return r;
  }
};

// --------------------------------------------------------------- texture ----

// Every byte value through the R8G8B8A8_SRGB sampler, without filtering
// effects: a 768 × 1 PNG holds each byte in 3 neighbouring texels (byte b in
// texels 3b .. 3b+2 of every channel, shifted per channel), and a 768 × 1
// film sees the plane so that pixel k covers texel k's footprint; the middle
// texel's pixel only blends equal texels, so each of its samples is exactly
// tint · decode(b). Checks the decode against the IEC curve within
// kSrgbDecodeAllowance and prints the device's largest error.
TEST_F(VulkanSurface, SrgbTextureDecodeEveryByte) {
  const int W = 768;
  auto dir = test::temp_dir("vk_surface_srgb_bytes");
  auto byte_of = [](int texel, int c) { return (texel / 3 + 85 * c) % 256; };
  Image img = make_image(W, 1);
  for (int x = 0; x < W; ++x)
    for (int c = 0; c < 3; ++c) img.at(x, 0, c) = float(test::srgb_to_linear(byte_of(x, c) / 255.0));
  const auto png = dir / "bytes.png";
  write_image(png, img);

  Scene s = test::analytic_base_scene(W, 1, 4);
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = 1;
  // Half-width 0.4 at distance 5 = the plane's 4 units.
  s.camera.fov_deg = 2.0 * std::atan(0.4 / W) * 180.0 / std::numbers::pi;
  const glm::dvec3 tint(1.0, 0.75, 0.5);
  Shape plane = test::plane_shape({0, 0, 0}, {0, 0, 1}, {4, 4}, tint);
  plane.texture = png;
  s.shapes.push_back(plane);
  RenderResult r = render(s);

  auto texel_x = [&](double fx) {  // continuous texel coordinate X = u·W − ½ at film x
    const glm::dvec3 d = test::film_ray(s.camera, W, 1, fx, 0.5);
    const glm::dvec3 p = s.camera.position + (-s.camera.position.z / d.z) * d;
    return (p.x / 4.0 + 0.5) * W - 0.5;
  };
  int checked = 0, worst_byte = -1;
  double worst = 0.0, worst_rel = 0.0;
  for (int x = 0; x < W; ++x) {
    const double a = texel_x(x), b = texel_x(x + 1), lo = std::min(a, b), hi = std::max(a, b);
    const int t = int(std::lround(0.5 * (lo + hi)));
    if (t % 3 != 1 || lo < t - 0.75 || hi > t + 0.75) continue;  // must blend only texels of one byte
    ++checked;
    const glm::dvec3 m = pixel_mean(r, x, 0);
    for (int c = 0; c < 3; ++c) {
      const double want = tint[c] * test::srgb_to_linear(byte_of(t, c) / 255.0);
      const double err = m[c] - want;
      EXPECT_NEAR(m[c], want, kSrgbDecodeAllowance) << "byte " << byte_of(t, c) << " channel " << c;
      if (std::abs(err) > worst) worst = std::abs(err), worst_byte = byte_of(t, c);
      if (want > 0) worst_rel = std::max(worst_rel, std::abs(err) / want);
    }
  }
  EXPECT_EQ(checked, 256);
  std::printf("sRGB decode on %s: largest error %.2e (byte %d), largest relative %.2e, over %d pixels x 3\n",
              vulkan_backend().device_name().c_str(), worst, worst_byte, worst_rel, checked);
}

// ----------------------------------------------------------- GPU vs CPU ----

void expect_same(const RenderResult& gpu, const RenderResult& cpu, double tolerance, double max_se_bias,
                 const char* what) {
  ZTestReport rep = test::ztest_images(gpu, cpu, pooled(tolerance));
  EXPECT_TRUE(rep.ok) << what << ": " << rep.summary();
  EXPECT_LE(rep.se_bias, max_se_bias) << what << ": " << rep.summary();
  std::printf("%s: %s (GPU %.2f s, CPU %.2f s)\n", what, rep.summary().c_str(), gpu.seconds, cpu.seconds);
}

// assets/scenes/terrain_explosion.json at 32 × 18: the textured mountain
// (12 800 triangles through the BVH, rock.png as SRGB8), the sky EXR, the
// scattering fire vdb, collision estimator.
Scene small_terrain_explosion(int spp) {
  Scene s = load_scene(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/scenes/terrain_explosion.json");
  s.film.width = 32;
  s.film.height = 18;
  s.film.spp = spp;
  s.film.seed = 11;
  return s;
}

// The samples split between the backends by their cost: a CPU sample costs
// ~3× a lavapipe one here, and the bias's variance is the sum of the two
// images' (σ²/n_gpu + σ²/n_cpu), so 3072 + 1280 spp give a pooled SE of
// ~0.40 %, under the 0.5 % asked, in ~85 % of the time of 2048 + 2048 (0.37 %).
constexpr int kTerrainGpuSpp = 3072, kTerrainCpuSpp = 1280;

TEST_F(VulkanSurface, AgreesWithCpuOnSmallTerrainExplosion) {
  Scene s = small_terrain_explosion(kTerrainGpuSpp);
  RenderResult gpu = render(s);
  Scene c = small_terrain_explosion(kTerrainCpuSpp);
  c.film.seed = 12;
  RenderResult cpu = render_cpu(c);
  expect_same(gpu, cpu, 0.01, 0.005, "terrain_explosion 32x18");
  // Alpha (docs/compositing.md): the terrain is opaque, the fire above the
  // horizon partly so.
  expect_same(test::alpha_image(gpu), test::alpha_image(cpu), 0.01, 0.005, "terrain_explosion 32x18 alpha");
}

// An emissive, scattering, chromatic homogeneous sphere above a textured plane
// (sRGB PNG) under a lat-long environment map (rotated), Z up: surfaces lit by
// the medium and by the sky, the medium lit by the sky and by the plane.
Scene emissive_medium_over_plane(const std::filesystem::path& dir, int spp, uint32_t seed, double env_rotation) {
  const test::TexelBytes bytes;
  const auto png = test::write_texel_png(bytes, dir);
  const auto exr = dir / "sky.exr";
  if (!std::filesystem::exists(exr)) write_image(exr, test::env_pattern_image());
  Scene s = test::analytic_base_scene(32, 24, spp);
  s.film.seed = seed;
  s.camera.position = {1.0, -6.0, 2.5};
  s.camera.look_at = {0.0, 0.0, 0.6};
  s.camera.up = {0, 0, 1};
  s.integrator.max_depth = 6;
  s.integrator.emission_estimator = EmissionEstimator::Collision;
  s.background = glm::dvec3(5.0);  // hidden by the environment
  s.environment = Environment{exr, 0.5, env_rotation};
  Shape plane = test::plane_shape({0, 0, 0}, {0, 0, 1}, {6, 6}, {0.9, 0.85, 0.8});
  plane.texture = png;
  s.shapes.push_back(plane);
  s.media.push_back(test::homogeneous_sphere("fire", {0.2, 0.3, 1.2}, 0.9, {0.8, 0.5, 0.3}, {1.0, 1.5, 2.0}, 0.3,
                                             glm::dvec3(3.0, 1.5, 0.5)));
  return s;
}

TEST_F(VulkanSurface, AgreesWithCpuOnEmissiveMediumOverTexturedPlane) {
  auto dir = test::temp_dir("vk_surface_medium_plane");
  // 512 spp: the pooled bias's SE is ~0.07 %, under the 0.25 % asked of it
  // and a seventh of the 0.5 % tolerance; the 5 % brighter reference still
  // lies ~7 SE past the tolerance.
  const int spp = 512;
  RenderResult gpu = render(emissive_medium_over_plane(dir, spp, 21, 60.0));
  RenderResult cpu = render_cpu(emissive_medium_over_plane(dir, spp, 22, 60.0));
  expect_same(gpu, cpu, 0.005, 0.0025, "emissive medium over textured plane");
  // The comparison can fail: the CPU reference with the sky turned the other
  // way, and with 5 % more emission (-1 % in the image), are both rejected.
  Scene turned = emissive_medium_over_plane(dir, spp / 2, 23, -60.0);
  ZTestReport rep_turned = test::ztest_images(gpu, render_cpu(turned), pooled());
  EXPECT_FALSE(rep_turned.ok) << rep_turned.summary();
  std::printf("vs CPU with the sky at -60 deg: %s\n", rep_turned.summary().c_str());
  Scene brighter = emissive_medium_over_plane(dir, spp / 2, 24, 60.0);
  brighter.media[0].emission.scale *= 1.05;
  ZTestReport rep_bright = test::ztest_images(gpu, render_cpu(brighter), pooled());
  EXPECT_FALSE(rep_bright.ok) << rep_bright.summary();
  std::printf("vs CPU with 5 %% more emission: %s\n", rep_bright.summary().c_str());
}

}  // namespace
}  // namespace pyrolume
