// The Vulkan backend with surfaces and the environment map (issue 6, BSDF and
// phase sampling only), validation layers on (any message fails):
//  - closed forms where every sample's value is known (furnaces, max_depth 0,
//    an occluding plane), per pixel;
//  - every byte through the R8G8B8A8_SRGB sampler against the IEC curve;
//  - the linearised, v-flipped texture (sRGB PNG and float EXR) and the
//    lat-long orientation against expectations computed here, by z-tests that
//    must also REJECT the wrong conventions (no flip, no sRGB decode,
//    unrotated, mirrored, Y-up);
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

#include "light/EnvironmentMap.h"
#include "render/Backend.h"
#include "render/cpu/CpuRenderer.h"
#include "scene/Scene.h"
#include "support/VulkanFixture.h"
#include "support/AnalyticScenes.h"
#include "support/Stats.h"
#include "support/SurfaceScenes.h"
#include "support/TestSupport.h"

namespace pyrolume {
namespace {

using test::ZTestOptions;
using test::ZTestReport;

using test::pixel_mean;
using test::pixel_spread;
using test::pooled;

// Per-sample values on the GPU are float: a product of a few floats or a
// bilinear blend of equal texels is within a few ulps of the exact value.
constexpr double kFloatTol = 2e-6;

class VulkanSurface : public test::VulkanFixture {
 protected:
  static RenderResult render_cpu(const Scene& s) {
    CpuRenderer cpu;
    RenderResult r = cpu.render(s, test::settings_for(s), {});
    EXPECT_EQ(cpu.majorant_violations(), 0u);
    EXPECT_EQ(r.nonfinite_samples, 0u);
    return r;
  }

};

// ------------------------------------------------------------ furnaces ----

// A convex diffuse sphere under a constant sky: a path that reaches it bounces
// once and escapes, so every sample of a pixel fully on the sphere is
// albedo · sky, and 0 with max_depth 0; pixels fully off it are the sky. An
// escaped ray leaving into the sphere (wrong side) would pick up the albedo
// twice; light leaking through would show in the max_depth 0 case.
struct ConvexSphereCase {
  Scene scene;
  glm::dvec3 center{0.3, -0.2, 0.0};
  double radius = 1.0;
};

ConvexSphereCase convex_sphere_case(glm::dvec3 albedo, glm::dvec3 background, int max_depth) {
  ConvexSphereCase k;
  k.scene = test::analytic_base_scene(32, 24, 16);
  k.scene.background = background;
  k.scene.integrator.max_depth = max_depth;
  k.scene.shapes.push_back(test::sphere_shape(k.center, k.radius, albedo));
  return k;
}

// +1 fully on the sphere, −1 fully off, 0 silhouette (margin ≫ a pixel).
int classify(const ConvexSphereCase& k, int x, int y) {
  const Scene& s = k.scene;
  glm::dvec3 d = test::film_ray(s.camera, s.film.width, s.film.height, x + 0.5, y + 0.5);
  glm::dvec3 oc = k.center - s.camera.position;
  double perp = glm::length(oc - glm::dot(oc, d) * d);
  if (perp < k.radius - 0.25) return 1;
  if (perp > k.radius + 0.25) return -1;
  return 0;
}

// Returns the number of pixel-channels that broke the expectation (so the
// caller can also show that a wrong expectation is rejected).
int check_convex_sphere(const ConvexSphereCase& k, const RenderResult& r, glm::dvec3 on, glm::dvec3 off,
                        bool report = true) {
  int n_on = 0, n_off = 0, bad = 0;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const int cls = classify(k, x, y);
      const glm::dvec3 m = pixel_mean(r, x, y);
      if (cls == 0) {
        for (int c = 0; c < 3; ++c) {
          const double lo = std::min(on[c], off[c]), hi = std::max(on[c], off[c]);
          if (!(m[c] >= lo - kFloatTol * (1 + lo) && m[c] <= hi + kFloatTol * (1 + hi))) {
            ++bad;
            if (report) ADD_FAILURE() << "silhouette pixel " << x << "," << y << " c " << c << ": " << m[c];
          }
        }
        continue;
      }
      const glm::dvec3 want = cls > 0 ? on : off;
      (cls > 0 ? n_on : n_off)++;
      for (int c = 0; c < 3; ++c)
        if (!(std::abs(m[c] - want[c]) <= kFloatTol * (1 + want[c]))) {
          ++bad;
          if (report) ADD_FAILURE() << "pixel " << x << "," << y << " c " << c << ": " << m[c] << " want " << want[c];
        }
      if (report) EXPECT_LE(pixel_spread(r, x, y), 1e-6) << "pixel " << x << "," << y;
    }
  EXPECT_GT(n_on, 50);
  EXPECT_GT(n_off, 50);
  return bad;
}

TEST_F(VulkanSurface, FurnaceConvexSphereAlbedoOneIsOne) {
  ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(1.0), 100);
  RenderResult r = render(k.scene);
  EXPECT_EQ(check_convex_sphere(k, r, glm::dvec3(1.0), glm::dvec3(1.0)), 0);
  EXPECT_GT(r.events, 0.0);
  // Chromatic: albedo · background on the sphere; a sphere that reflected
  // twice (escaping into itself) would show albedo² · background.
  const glm::dvec3 a(0.25, 0.5, 0.75), bg(0.8, 1.0, 1.2);
  ConvexSphereCase c = convex_sphere_case(a, bg, 8);
  RenderResult rc = render(c.scene);
  EXPECT_EQ(check_convex_sphere(c, rc, a * bg, bg), 0);
  EXPECT_GT(check_convex_sphere(c, rc, a * a * bg, bg, false), 100) << "the check cannot fail";
}

// The same furnace with the sky from a uniform EXR (scale, rotation): escaping
// rays read the map, not background.rgb (9, which would show). BSDF sampling
// alone gives the exact value (light sampling the map would add noise to it).
TEST_F(VulkanSurface, FurnaceUnderUniformEnvironmentMap) {
  auto dir = test::temp_dir("vk_surface_env_uniform");
  const auto exr = dir / "uniform.exr";
  write_image(exr, test::uniform_image(4, 2, {0.25f, 0.5f, 0.75f}));  // exact in half and float
  {
    ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(9.0), 100);
    k.scene.environment = Environment{exr, 4.0, 45.0};
    k.scene.integrator.mis = false;
    const glm::dvec3 sky = 4.0 * glm::dvec3(0.25, 0.5, 0.75);
    EXPECT_EQ(check_convex_sphere(k, render(k.scene), sky, sky), 0);
  }
  {
    const glm::dvec3 a(0.5, 0.8, 1.0), sky = 2.0 * glm::dvec3(0.25, 0.5, 0.75);
    ConvexSphereCase k = convex_sphere_case(a, glm::dvec3(9.0), 4);
    k.scene.environment = Environment{exr, 2.0, -30.0};
    k.scene.integrator.mis = false;
    EXPECT_EQ(check_convex_sphere(k, render(k.scene), a * sky, sky), 0);
  }
}

TEST_F(VulkanSurface, MaxDepthZeroShowsBlackSphere) {
  ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(1.0), 0);
  RenderResult r = render(k.scene);
  EXPECT_EQ(check_convex_sphere(k, r, glm::dvec3(0.0), glm::dvec3(1.0)), 0);
  EXPECT_GT(r.events, 0.0);  // the bounce that max_depth ends still counts
  EXPECT_GT(check_convex_sphere(k, r, glm::dvec3(1.0), glm::dvec3(1.0), false), 100) << "the check cannot fail";
}

// Every camera sample meets exactly one surface (an infinite plane filling the
// view) and escapes: one event per camera sample, like the CPU.
TEST_F(VulkanSurface, SurfaceBounceCountsAsOneEvent) {
  Scene s = test::analytic_base_scene(8, 8, 8);
  s.background = glm::dvec3(1.0);
  s.shapes.push_back(test::plane_shape({0, 0, 1}, {0, 0, -1}, {0, 0}, glm::dvec3(0.5)));
  RenderResult r = render(s);
  EXPECT_DOUBLE_EQ(r.events, 8.0 * 8.0 * 8.0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_NEAR(pixel_mean(r, x, y).x, 0.5, 1e-6);
}

// --------------------------------------------------------------- texture ----

// The exact image with a per-channel allowance for a known, bounded device
// error: the expected value moves toward the render's mean by at most
// `allowance` (absolute) before the z-test. 0 = the plain z-test.
std::function<glm::dvec3(int, int)> with_allowance(const RenderResult& r, std::function<glm::dvec3(int, int)> exact,
                                                   double allowance) {
  return [&r, exact, allowance](int x, int y) {
    const glm::dvec3 e = exact(x, y), m = pixel_mean(r, x, y);
    return glm::clamp(m, e - allowance, e + allowance);
  };
}

// lavapipe decodes R8G8B8A8_SRGB texels with an approximation of the IEC
// curve (measured here on llvmpipe / LLVM 15, every byte value on a uniform
// texture: |error| <= 1.2e-3 absolute, largest near byte 215; up to 0.74 %
// relative near byte 85 and 2.5 % for bytes 1..10, i.e. within half an 8-bit
// step). With 128 spp that is a few σ on a smooth texture, so the sRGB z-test
// allows 1.5e-3 per channel (×tint <= 1). The wrong conventions are off by
// 0.05 .. 0.6 and fail by hundreds of σ either way; the linear (EXR) texture
// below is held to the plain z-test.
constexpr double kSrgbDecodeAllowance = 1.5e-3;

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
              backend_->device_name().c_str(), worst, worst_byte, worst_rel, checked);
}

// A textured plane under a white sky, max_depth 1: a sample that hits the
// plane bounces once and escapes, L = tint · albedo(uv), so each pixel's mean
// is the texture averaged over the pixel's footprint. The expectation decodes
// the PNG's bytes with the IEC curve and applies the documented v flip and
// bilinear/wrap lookup independently. On the GPU the 8-bit texture is an
// R8G8B8A8_SRGB image (the sampler decodes, then filters). Taking the bytes as
// linear, or leaving out the flip, must fail the same z-test. The same texels
// as a float EXR (no decoding, R32G32B32A32_SFLOAT) must give the same image.
TEST_F(VulkanSurface, TexturedPlaneShowsLinearisedTexture) {
  const test::TexelBytes bytes;
  auto dir = test::temp_dir("vk_surface_texture");
  const auto png = test::write_texel_png(bytes, dir);
  const auto exr = dir / "albedo.exr";
  {
    Image img = make_image(bytes.w, bytes.h);
    for (size_t k = 0; k < bytes.rgb.size(); ++k) img.rgb[k] = float(test::srgb_to_linear(bytes.rgb[k] / 255.0));
    write_image(exr, img);
  }

  Scene s = test::analytic_base_scene(24, 24, 128);
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = 1;
  // Plane z = 0, normal +z (the camera sees its back side), 4 × 4 units;
  // u axis = world +X projected, v axis = cross(n, u) = +Y.
  const glm::dvec3 tint(1.0, 0.9, 0.8);
  Shape plane = test::plane_shape({0, 0, 0}, {0, 0, 1}, {4, 4}, tint);
  plane.texture = png;
  s.shapes.push_back(plane);
  RenderResult r = render(s);

  auto exact_for = [&](test::TexVariant v) {
    return test::exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
      const glm::dvec3 d = test::film_ray(s.camera, s.film.width, s.film.height, fx, fy);
      const glm::dvec3 p = s.camera.position + (-s.camera.position.z / d.z) * d;
      if (std::abs(p.x) > 2.0 || std::abs(p.y) > 2.0) {
        *sig = -1;
        return s.background;
      }
      return tint * test::texture_lookup(bytes, {p.x / 4.0 + 0.5, p.y / 4.0 + 0.5}, v, sig);
    });
  };
  const auto exact = exact_for(test::TexVariant::Correct);
  ZTestReport ok = test::ztest_against_exact(r, with_allowance(r, exact, kSrgbDecodeAllowance), pooled());
  EXPECT_TRUE(ok.ok) << ok.summary();
  std::printf("sRGB texture (allowance %.1e): %s\n", kSrgbDecodeAllowance, ok.summary().c_str());
  ZTestReport strict = test::ztest_against_exact(r, exact, pooled());
  std::printf("sRGB texture, no allowance (informative): %s\n", strict.summary().c_str());
  const struct {
    test::TexVariant v;
    const char* what;
  } wrong[] = {{test::TexVariant::NoFlip, "without the v flip"}, {test::TexVariant::NoDecode, "without sRGB decode"}};
  for (const auto& w : wrong) {
    ZTestReport bad =
        test::ztest_against_exact(r, with_allowance(r, exact_for(w.v), kSrgbDecodeAllowance), pooled());
    EXPECT_FALSE(bad.fraction_ok) << w.what << ": " << bad.summary();
    std::printf("texture %s: %s\n", w.what, bad.summary().c_str());
  }

  s.shapes[0].texture = exr;
  RenderResult lin = render(s);
  ZTestReport ok_lin = test::ztest_against_exact(lin, exact, pooled());
  EXPECT_TRUE(ok_lin.ok) << ok_lin.summary();
  std::printf("float EXR texture: %s\n", ok_lin.summary().c_str());
  ZTestReport lin_flip = test::ztest_against_exact(lin, exact_for(test::TexVariant::NoFlip), pooled());
  EXPECT_FALSE(lin_flip.fraction_ok) << lin_flip.summary();
}

// ---------------------------------------------------------- environment ----

// Camera rays straight to an 8 × 4 EXR written here (every texel different),
// scale 1.5, rotation_deg 30, camera +Z up: the GPU's env_radiance against the
// host EnvironmentMap::radiance (whose convention light_env_test and
// cpu_surface_test pin down independently), averaged over each pixel. The
// same z-test must reject the map unrotated, mirrored (u growing
// counter-clockwise) and read as +Y-up.
TEST_F(VulkanSurface, EnvironmentMapSeenByCameraRays) {
  auto dir = test::temp_dir("vk_surface_env");
  const auto exr = dir / "sky.exr";
  write_image(exr, test::env_pattern_image());

  const double scale = 1.5, rot = 30.0;
  Scene s = test::analytic_base_scene(32, 20, 32);
  s.camera.position = {0, 0, 0};
  s.camera.look_at = {1.0, 0.4, 0.3};
  s.camera.up = {0, 0, 1};
  s.camera.fov_deg = 100.0;
  s.background = glm::dvec3(7.0);  // must not be seen
  s.environment = Environment{exr, scale, rot};
  RenderResult r = render(s);
  EXPECT_EQ(r.events, 0.0);

  enum class Wrong { None, Unrotated, Mirrored, YUp };
  auto exact_for = [&](Wrong w) {
    const EnvironmentMap env = EnvironmentMap::load(exr, scale, w == Wrong::Unrotated ? 0.0 : rot);
    return test::exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
      glm::dvec3 d = test::film_ray(s.camera, s.film.width, s.film.height, fx, fy);
      if (w == Wrong::Mirrored) d.y = -d.y;
      if (w == Wrong::YUp) d = glm::dvec3(d.x, -d.z, d.y);  // what +Y would be if it were the zenith
      const glm::dvec2 uv = env.direction_to_uv(d);
      *sig = int(std::floor(uv.x * env.width() - 0.5)) * 1000 + int(std::floor(uv.y * env.height() - 0.5));
      return env.radiance(d);
    });
  };
  ZTestReport ok = test::ztest_against_exact(r, exact_for(Wrong::None), pooled());
  EXPECT_TRUE(ok.ok) << ok.summary();
  std::printf("environment: %s\n", ok.summary().c_str());
  const struct {
    Wrong w;
    const char* what;
  } wrong[] = {{Wrong::Unrotated, "unrotated"}, {Wrong::Mirrored, "mirrored (u counter-clockwise)"}, {Wrong::YUp, "+Y up"}};
  for (const auto& w : wrong) {
    ZTestReport bad = test::ztest_against_exact(r, exact_for(w.w), pooled());
    EXPECT_FALSE(bad.fraction_ok) << w.what << ": " << bad.summary();
    std::printf("environment %s: %s\n", w.what, bad.summary().c_str());
  }
}

// ----------------------------------------------------------- occlusion ----

// An infinite plane between the camera and a bright emissive, scattering
// sphere: the camera sees only the plane, whose bounce leaves toward the
// camera's side where there is nothing, so every sample is exactly
// albedo · background (no glow may leak through). Without the plane the glow
// shows. Both emission estimators.
TEST_F(VulkanSurface, PlaneOccludesEmissiveMedium) {
  const glm::dvec3 a(0.5, 0.25, 0.8), bg(0.2, 0.4, 0.6);
  for (const char* estimator : {"absorption", "collision"}) {
    Scene s = test::analytic_base_scene(16, 16, 16);
    s.background = bg;
    s.integrator.emission_estimator = estimator;
    s.media.push_back(test::homogeneous_sphere("glow", {0, 0, 0}, 1.0, {2, 2, 2}, {0.5, 0.5, 0.5}, 0.0,
                                               glm::dvec3(5.0, 3.0, 1.0)));
    Scene open = s;
    s.shapes.push_back(test::plane_shape({0, 0, -1.5}, {0, 0, 1}, {0, 0}, a));
    RenderResult r = render(s);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(m[c], a[c] * bg[c], kFloatTol) << estimator << " " << x << "," << y;
      }
    RenderResult glow = render(open);
    EXPECT_GT(pixel_mean(glow, 8, 8).x, 1.0) << estimator;
  }
}

// ------------------------------------------- mesh + medium white furnace ----

// A concave world: an open-topped box (OBJ written here, through the BVH) with
// a sphere standing in it and a scattering, non-absorbing, non-emitting medium
// overlapping both (surfaces inside the medium, rays leaving surfaces inside
// it). Albedo 1 everywhere and a white sky: every escaping path returns 1.
// Grey σs: each sample is 1 up to float rounding. Chromatic σs: the GPU's
// spectral tracking makes per-channel weights that are 1 only in expectation,
// so a z-test. max_depth 1 must darken (the scene does inter-reflect).
Scene concave_furnace_scene(const std::filesystem::path& obj, int max_depth, glm::dvec3 sigma_s) {
  Scene s = test::analytic_base_scene(24, 24, 16);
  s.camera.position = {0.6, 4.0, -2.5};
  s.camera.look_at = {0.0, -0.5, 0.0};
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = max_depth;
  s.shapes.push_back(test::mesh_shape(obj, glm::dvec3(1.0)));
  s.shapes.push_back(test::sphere_shape({0.2, -0.4, 0.1}, 0.55, glm::dvec3(1.0)));
  s.media.push_back(test::homogeneous_box("fog", {-1.5, -1.5, -1.5}, {1.5, 0.5, 1.5}, glm::dvec3(0.0), sigma_s, 0.4,
                                          std::nullopt));
  return s;
}

TEST_F(VulkanSurface, FurnaceConcaveMeshSphereAndMediumIsOne) {
  auto obj = test::write_open_box_obj(test::temp_dir("vk_surface_furnace"));
  for (const char* estimator : {"absorption", "collision"}) {
    Scene s = concave_furnace_scene(obj, 1000, glm::dvec3(1.0));
    s.integrator.emission_estimator = estimator;
    RenderResult r = render(s);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], 1.0, 1e-4) << estimator << " pixel " << x << "," << y;
      }
    EXPECT_GT(r.events / (double(r.width) * r.height * r.spp), 1.5) << "paths should bounce and scatter";
  }
  {
    Scene s = concave_furnace_scene(obj, 1000, {0.6, 1.0, 1.6});
    s.film.spp = 256;
    RenderResult r = render(s);
    ZTestReport rep = test::ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); }, pooled());
    EXPECT_LE(rep.se_bias, 0.0025) << rep.summary();
    EXPECT_TRUE(rep.ok) << rep.summary();
    std::printf("chromatic concave furnace: %s\n", rep.summary().c_str());
  }
  // Surface bounces and medium scatterings share max_depth: one event only and
  // the concave box loses light.
  RenderResult shallow = render(concave_furnace_scene(obj, 1, glm::dvec3(1.0)));
  double total = 0.0;
  for (double v : shallow.sum) total += v;
  EXPECT_LT(total / (double(shallow.sum.size()) * shallow.spp), 0.9);
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

constexpr int kTerrainSpp = 2048;

TEST_F(VulkanSurface, AgreesWithCpuOnSmallTerrainExplosion) {
  Scene s = small_terrain_explosion(kTerrainSpp);
  RenderResult gpu = render(s);
  Scene c = s;
  c.film.seed = 12;
  RenderResult cpu = render_cpu(c);
  expect_same(gpu, cpu, 0.01, 0.005, "terrain_explosion 32x18");
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
  s.integrator.emission_estimator = "collision";
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
  const int spp = 1024;
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
