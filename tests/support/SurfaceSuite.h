#pragma once
// Surfaces and the environment map on either backend (issue 6, BSDF and phase
// sampling only): closed forms where every sample's value is known (furnaces,
// max_depth 0, an occluding plane), per pixel; the linearised, v-flipped
// texture (sRGB PNG and float EXR) and the lat-long orientation against
// expectations computed here, by z-tests that must also REJECT the wrong
// conventions. One body per case, instantiated for the CPU reference by
// tests/unit/cpu_surface_test.cpp and for Vulkan by
// tests/vulkan/vulkan_surface_test.cpp (BackendSuite.h explains); the cases
// only one backend has stay in those files.
//
// Per backend: a sample's value that is exact in closed form is held to 1e-12
// on the CPU (double) and to kFloatTol·(1 + value) on the GPU (float: a
// product of a few floats or a bilinear blend of equal texels is within a few
// ulps); lavapipe's sRGB decode is allowed kSrgbDecodeAllowance.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "image/Image.h"
#include "image/ImageIo.h"
#include "support/AnalyticScenes.h"
#include "support/BackendSuite.h"
#include "support/Stats.h"
#include "support/SurfaceScenes.h"
#include "support/TestSupport.h"

namespace pyrolume::test {

// GPU per-sample values are float (see above).
inline constexpr double kFloatTol = 2e-6;

// lavapipe decodes R8G8B8A8_SRGB texels with an approximation of the IEC
// curve (measured on llvmpipe / LLVM 15, every byte value on a uniform
// texture: |error| <= 1.2e-3 absolute, largest near byte 215; up to 0.74 %
// relative near byte 85 and 2.5 % for bytes 1..10, i.e. within half an 8-bit
// step). With 128 spp that is a few σ on a smooth texture, so the GPU's sRGB
// z-test allows 1.5e-3 per channel (×tint <= 1). The wrong conventions are
// off by 0.05 .. 0.6 and fail by hundreds of σ either way; the linear (EXR)
// texture is held to the plain z-test, and the CPU (which decodes exactly)
// to the plain z-test throughout.
inline constexpr double kSrgbDecodeAllowance = 1.5e-3;

// The exact image with a per-channel allowance for a known, bounded device
// error: the expected value moves toward the render's mean by at most
// `allowance` (absolute) before the z-test. 0 = the plain z-test.
inline std::function<glm::dvec3(int, int)> with_allowance(const RenderResult& r,
                                                          std::function<glm::dvec3(int, int)> exact,
                                                          double allowance) {
  return [&r, exact, allowance](int x, int y) {
    const glm::dvec3 e = exact(x, y), m = pixel_mean(r, x, y);
    return glm::clamp(m, e - allowance, e + allowance);
  };
}

// A convex diffuse sphere under a constant sky: a path that reaches it bounces
// once and escapes (nothing else to hit), so EVERY sample of a pixel fully on
// the sphere is exactly albedo · background, and 0 when max_depth = 0 (the
// bounce would be the first scattering event). Pixels fully off it are
// exactly the background. The escaped ray must leave on the side it arrived:
// a direction into the sphere would meet its inside and pick up albedo twice.
struct ConvexSphereCase {
  Scene scene;
  glm::dvec3 center{0.3, -0.2, 0.0};
  double radius = 1.0;
};

inline ConvexSphereCase convex_sphere_case(glm::dvec3 albedo, glm::dvec3 background, int max_depth) {
  ConvexSphereCase k;
  k.scene = analytic_base_scene(32, 24, 16);
  k.scene.background = background;
  k.scene.integrator.max_depth = max_depth;
  k.scene.shapes.push_back(sphere_shape(k.center, k.radius, albedo));
  return k;
}

// Classify pixels by the distance of their centre ray from the sphere's centre
// (margin ≫ the pixel footprint there, ~0.09 units): +1 fully on it, −1 fully
// off, 0 silhouette.
inline int classify(const ConvexSphereCase& k, int x, int y) {
  const Scene& s = k.scene;
  glm::dvec3 d = film_ray(s.camera, s.film.width, s.film.height, x + 0.5, y + 0.5);
  glm::dvec3 oc = k.center - s.camera.position;
  double perp = glm::length(oc - glm::dot(oc, d) * d);
  if (perp < k.radius - 0.25) return 1;
  if (perp > k.radius + 0.25) return -1;
  return 0;
}

// The documented lat-long convention (EnvironmentMap.h, Blender's), written
// here independently of light/EnvironmentMap: +Z up, θ from +Z, φ = atan2(y,
// x), u = (π − φ)/(2π), v = θ/π (row 0 = top = +Z); rotation_deg turns the map
// about +Z, so a direction d sees the unrotated map at Rz(−rotation)·d;
// bilinear between texel centres, wrapping in u, clamping in v; × scale.
inline glm::dvec3 env_radiance(const Image& e, glm::dvec3 d, double scale, double rot_deg, int* sig) {
  constexpr double kPi = std::numbers::pi;
  d = glm::normalize(d);
  const double r = rot_deg * kPi / 180.0;
  const double x = std::cos(r) * d.x + std::sin(r) * d.y, y = -std::sin(r) * d.x + std::cos(r) * d.y;
  double u = (kPi - std::atan2(y, x)) / (2.0 * kPi);
  u -= std::floor(u);
  const double v = std::acos(std::clamp(d.z, -1.0, 1.0)) / kPi;
  const double X = u * e.width - 0.5, Y = v * e.height - 0.5;
  const double x0 = std::floor(X), y0 = std::floor(Y), fx = X - x0, fy = Y - y0;
  if (sig) *sig = int(x0) * 1000 + int(y0);
  auto texel = [&](int i, int j) {
    i = ((i % e.width) + e.width) % e.width;
    j = std::clamp(j, 0, e.height - 1);
    const size_t k = (size_t(j) * e.width + i) * 3;
    return glm::dvec3(e.rgb[k], e.rgb[k + 1], e.rgb[k + 2]);
  };
  const int i = int(x0), j = int(y0);
  return scale * ((1 - fy) * ((1 - fx) * texel(i, j) + fx * texel(i + 1, j)) +
                  fy * ((1 - fx) * texel(i, j + 1) + fx * texel(i + 1, j + 1)));
}

// A concave world: an open-topped box (an OBJ mesh, through the BVH) with a
// sphere standing in it and a scattering, non-absorbing, non-emitting medium
// overlapping both (rays start inside it, surfaces sit inside it).
inline Scene concave_furnace_scene(const std::filesystem::path& obj, int max_depth, glm::dvec3 sigma_s) {
  Scene s = analytic_base_scene(24, 24, 16);
  s.camera.position = {0.6, 4.0, -2.5};
  s.camera.look_at = {0.0, -0.5, 0.0};
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = max_depth;
  s.shapes.push_back(mesh_shape(obj, glm::dvec3(1.0)));
  s.shapes.push_back(sphere_shape({0.2, -0.4, 0.1}, 0.55, glm::dvec3(1.0)));
  s.media.push_back(homogeneous_box("fog", {-1.5, -1.5, -1.5}, {1.5, 0.5, 1.5}, glm::dvec3(0.0), sigma_s, 0.4,
                                    std::nullopt));
  return s;
}

class SurfaceFixture : public BackendFixture {
 protected:
  using BackendFixture::BackendFixture;

  // How far a pixel mean that is exact in closed form may be from `value`.
  double exact_tol(double value) const { return per_backend(1e-12, kFloatTol * (1 + std::abs(value))); }

  // Returns the number of pixel-channels that broke the expectation (so the
  // caller can also show that a wrong expectation is rejected).
  int check_convex_sphere(const ConvexSphereCase& k, const RenderResult& r, glm::dvec3 on, glm::dvec3 off,
                          bool report = true) const {
    const double spread_tol = per_backend(1e-12, 1e-6);
    int n_on = 0, n_off = 0, bad = 0;
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const int cls = classify(k, x, y);
        const glm::dvec3 m = pixel_mean(r, x, y);
        if (cls == 0) {
          for (int c = 0; c < 3; ++c) {
            const double lo = std::min(on[c], off[c]), hi = std::max(on[c], off[c]);
            if (!(m[c] >= lo - exact_tol(lo) && m[c] <= hi + exact_tol(hi))) {
              ++bad;
              if (report) ADD_FAILURE() << "silhouette pixel " << x << "," << y << " c " << c << ": " << m[c];
            }
          }
          continue;
        }
        const glm::dvec3 want = cls > 0 ? on : off;
        (cls > 0 ? n_on : n_off)++;
        for (int c = 0; c < 3; ++c)
          if (!(std::abs(m[c] - want[c]) <= exact_tol(want[c]))) {
            ++bad;
            if (report) ADD_FAILURE() << "pixel " << x << "," << y << " c " << c << ": " << m[c] << " want " << want[c];
          }
        if (report) EXPECT_LE(pixel_spread(r, x, y), spread_tol) << "pixel " << x << "," << y;
      }
    EXPECT_GT(n_on, 50);
    EXPECT_GT(n_off, 50);
    return bad;
  }
};

using Surface = BackendSuite<SurfaceFixture>;

// ------------------------------------------------------------ furnaces ----

// Albedo 1 under a white sky: 1 everywhere. Chromatic: albedo · background on
// the sphere; a sphere that reflected twice (escaping into itself) would show
// albedo² · background, which the check rejects.
TEST_P(Surface, FurnaceConvexSphereAlbedoOneIsOne) {
  ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(1.0), 100);
  RenderResult r = render(k.scene);
  EXPECT_EQ(check_convex_sphere(k, r, glm::dvec3(1.0), glm::dvec3(1.0)), 0);
  EXPECT_GT(r.events, 0.0);
  const glm::dvec3 a(0.25, 0.5, 0.75), bg(0.8, 1.0, 1.2);
  ConvexSphereCase c = convex_sphere_case(a, bg, 8);
  RenderResult rc = render(c.scene);
  EXPECT_EQ(check_convex_sphere(c, rc, a * bg, bg), 0);
  EXPECT_GT(check_convex_sphere(c, rc, a * a * bg, bg, false), 100) << "the check cannot fail";
}

// One bounce: albedo · background on the sphere, whether max_depth allows one
// event or more.
TEST_P(Surface, ConvexSphereOneBounceIsAlbedoTimesBackground) {
  const glm::dvec3 a(0.25, 0.5, 0.75), bg(0.8, 1.0, 1.2);
  for (int depth : {1, 8}) {
    ConvexSphereCase k = convex_sphere_case(a, bg, depth);
    RenderResult r = render(k.scene);
    EXPECT_EQ(check_convex_sphere(k, r, a * bg, bg), 0) << "max_depth " << depth;
    EXPECT_GT(r.events, 0.0);
  }
}

// The same furnace with the sky from a uniform EXR (scale, rotation): escaping
// (scattered) rays read the map, not background.rgb (9, which would show).
// BSDF sampling alone gives the exact value (light sampling the map would add
// noise to it, so it is turned off).
TEST_P(Surface, FurnaceUnderUniformEnvironmentMap) {
  auto dir = temp_dir(backend_name() + "_surface_env_uniform");
  const auto exr = dir / "uniform.exr";
  write_image(exr, uniform_image(4, 2, {0.25f, 0.5f, 0.75f}));  // exact in half and float
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

TEST_P(Surface, MaxDepthZeroEndsAtTheSurface) {
  ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(1.0), 0);
  RenderResult r = render(k.scene);
  EXPECT_EQ(check_convex_sphere(k, r, glm::dvec3(0.0), glm::dvec3(1.0)), 0);
  EXPECT_GT(r.events, 0.0);  // the bounce that max_depth ends still counts
  EXPECT_GT(check_convex_sphere(k, r, glm::dvec3(1.0), glm::dvec3(1.0), false), 100) << "the check cannot fail";
}

// Every camera sample of this scene meets exactly one surface (an infinite
// plane filling the view) and escapes: events = one per camera sample.
TEST_P(Surface, SurfaceBounceCountsAsOneEvent) {
  Scene s = analytic_base_scene(8, 8, 8);
  s.background = glm::dvec3(1.0);
  s.shapes.push_back(plane_shape({0, 0, 1}, {0, 0, -1}, {0, 0}, glm::dvec3(0.5)));
  RenderResult r = render(s);
  EXPECT_DOUBLE_EQ(r.events, 8.0 * 8.0 * 8.0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_NEAR(pixel_mean(r, x, y).x, 0.5, per_backend(1e-12, 1e-6));
}

// Albedo 1 everywhere and a white sky in the concave world
// (concave_furnace_scene): every path that escapes returns exactly 1 (white
// furnace), whatever the number of bounces, with either estimator (grey σs:
// each sample is 1 up to rounding: double on the CPU, float on the GPU). With
// max_depth = 1 paths needing a second bounce die, so the image must darken
// (this scene does inter-reflect). On the GPU also chromatic σs: its spectral
// tracking makes per-channel weights that are 1 only in expectation, so a
// z-test.
TEST_P(Surface, FurnaceConcaveMeshSphereAndMediumIsOne) {
  auto obj = write_open_box_obj(temp_dir(backend_name() + "_surface_furnace"));
  for (const EmissionEstimator estimator : {EmissionEstimator::Absorption, EmissionEstimator::Collision}) {
    Scene s = concave_furnace_scene(obj, 1000, glm::dvec3(1.0));
    s.integrator.emission_estimator = estimator;
    RenderResult r = render(s);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(m[c], 1.0, per_backend(1e-12, 1e-4)) << to_string(estimator) << " pixel " << x << "," << y;
      }
    EXPECT_GT(r.events / (double(r.width) * r.height * r.spp), 1.5) << "paths should bounce and scatter";
  }
  if (vulkan()) {
    Scene s = concave_furnace_scene(obj, 1000, {0.6, 1.0, 1.6});
    s.film.spp = 256;
    RenderResult r = render(s);
    ZTestReport rep = ztest_against_exact(r, [](int, int) { return glm::dvec3(1.0); }, pooled());
    EXPECT_LE(rep.se_bias, 0.0025) << rep.summary();
    EXPECT_TRUE(rep.ok) << rep.summary();
    std::printf("chromatic concave furnace: %s\n", rep.summary().c_str());
  }
  // Surface bounces and medium scatterings share max_depth: allow one event
  // and the concave box loses light.
  RenderResult shallow = render(concave_furnace_scene(obj, 1, glm::dvec3(1.0)));
  double total = 0.0;
  for (double v : shallow.sum) total += v;
  EXPECT_LT(total / (double(shallow.sum.size()) * shallow.spp), 0.9);
}

// --------------------------------------------------------------- texture ----

// A textured plane under a white sky, max_depth 1: a sample that hits the
// plane bounces once and escapes, L = tint · albedo(uv), so each pixel's mean
// is the texture averaged over the pixel's footprint. The expectation decodes
// the PNG's bytes with the IEC curve and applies the documented v flip
// (uv (0, 0) = the image's bottom-left) and bilinear/wrap lookup
// independently. On the GPU the 8-bit texture is an R8G8B8A8_SRGB image (the
// sampler decodes, then filters). Taking the bytes as linear, or leaving out
// the flip, must fail the same z-test. The same texels as a float EXR (no
// decoding, R32G32B32A32_SFLOAT on the GPU) must give the same image.
TEST_P(Surface, TexturedPlaneShowsLinearisedTexture) {
  const double allowance = per_backend(0.0, kSrgbDecodeAllowance);
  const TexelBytes bytes;
  auto dir = temp_dir(backend_name() + "_surface_texture");
  const auto png = write_texel_png(bytes, dir);
  const auto exr = dir / "albedo.exr";
  {
    Image img = make_image(bytes.w, bytes.h);
    for (size_t k = 0; k < bytes.rgb.size(); ++k) img.rgb[k] = float(srgb_to_linear(bytes.rgb[k] / 255.0));
    write_image(exr, img);
  }

  Scene s = analytic_base_scene(24, 24, 128);
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = 1;
  // Plane z = 0, normal +z (the camera sees its back side), 4 × 4 units;
  // u axis = world +X projected, v axis = cross(n, u) = +Y.
  const glm::dvec3 tint(1.0, 0.9, 0.8);
  Shape plane = plane_shape({0, 0, 0}, {0, 0, 1}, {4, 4}, tint);
  plane.texture = png;
  s.shapes.push_back(plane);
  RenderResult r = render(s);

  auto exact_for = [&](TexVariant v) {
    return exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
      const glm::dvec3 d = film_ray(s.camera, s.film.width, s.film.height, fx, fy);
      const glm::dvec3 p = s.camera.position + (-s.camera.position.z / d.z) * d;
      if (std::abs(p.x) > 2.0 || std::abs(p.y) > 2.0) {
        *sig = -1;
        return s.background;
      }
      return tint * texture_lookup(bytes, {p.x / 4.0 + 0.5, p.y / 4.0 + 0.5}, v, sig);
    });
  };
  const auto exact = exact_for(TexVariant::Correct);
  ZTestReport ok = ztest_against_exact(r, with_allowance(r, exact, allowance), pooled());
  EXPECT_TRUE(ok.ok) << ok.summary();
  std::printf("sRGB texture (allowance %.1e): %s\n", allowance, ok.summary().c_str());
  if (allowance > 0.0) {
    ZTestReport strict = ztest_against_exact(r, exact, pooled());
    std::printf("sRGB texture, no allowance (informative): %s\n", strict.summary().c_str());
  }
  const struct {
    TexVariant v;
    const char* what;
  } wrong[] = {{TexVariant::NoFlip, "without the v flip"}, {TexVariant::NoDecode, "without sRGB decode"}};
  for (const auto& w : wrong) {
    ZTestReport bad = ztest_against_exact(r, with_allowance(r, exact_for(w.v), allowance), pooled());
    EXPECT_FALSE(bad.fraction_ok) << w.what << ": " << bad.summary();
    std::printf("texture %s: %s\n", w.what, bad.summary().c_str());
  }

  s.shapes[0].texture = exr;
  RenderResult lin = render(s);
  ZTestReport ok_lin = ztest_against_exact(lin, exact, pooled());
  EXPECT_TRUE(ok_lin.ok) << ok_lin.summary();
  std::printf("float EXR texture: %s\n", ok_lin.summary().c_str());
  ZTestReport lin_flip = ztest_against_exact(lin, exact_for(TexVariant::NoFlip), pooled());
  EXPECT_FALSE(lin_flip.fraction_ok) << lin_flip.summary();
}

// ---------------------------------------------------------- environment ----

// Camera rays straight to an 8 × 4 EXR written here (every texel different),
// scale 1.5, rotation_deg 30, camera +Z up, against env_radiance (the
// documented convention written independently above), averaged over each
// pixel. The same z-test must reject the map unrotated, mirrored (u growing
// counter-clockwise) and read as +Y-up.
TEST_P(Surface, EnvironmentMapSeenByCameraRays) {
  auto dir = temp_dir(backend_name() + "_surface_env");
  const auto exr = dir / "sky.exr";
  const Image texels = env_pattern_image();
  write_image(exr, texels);

  const double scale = 1.5, rot = 30.0;
  Scene s = analytic_base_scene(32, 20, 32);
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
    return exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
      glm::dvec3 d = film_ray(s.camera, s.film.width, s.film.height, fx, fy);
      if (w == Wrong::Mirrored) d.y = -d.y;                 // u growing counter-clockwise instead
      if (w == Wrong::YUp) d = glm::dvec3(d.x, -d.z, d.y);  // what +Y would be if it were the zenith
      return env_radiance(texels, d, scale, w == Wrong::Unrotated ? 0.0 : rot, sig);
    });
  };
  ZTestReport ok = ztest_against_exact(r, exact_for(Wrong::None), pooled());
  EXPECT_TRUE(ok.ok) << ok.summary();
  std::printf("environment: %s\n", ok.summary().c_str());
  const struct {
    Wrong w;
    const char* what;
  } wrong[] = {{Wrong::Unrotated, "unrotated"}, {Wrong::Mirrored, "mirrored (u counter-clockwise)"}, {Wrong::YUp, "+Y up"}};
  for (const auto& w : wrong) {
    ZTestReport bad = ztest_against_exact(r, exact_for(w.w), pooled());
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
TEST_P(Surface, PlaneOccludesEmissiveMedium) {
  const glm::dvec3 a(0.5, 0.25, 0.8), bg(0.2, 0.4, 0.6);
  for (const EmissionEstimator estimator : {EmissionEstimator::Absorption, EmissionEstimator::Collision}) {
    Scene s = analytic_base_scene(16, 16, 16);
    s.background = bg;
    s.integrator.emission_estimator = estimator;
    s.media.push_back(
        homogeneous_sphere("glow", {0, 0, 0}, 1.0, {2, 2, 2}, {0.5, 0.5, 0.5}, 0.0, glm::dvec3(5.0, 3.0, 1.0)));
    Scene open = s;
    s.shapes.push_back(plane_shape({0, 0, -1.5}, {0, 0, 1}, {0, 0}, a));
    RenderResult r = render(s);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(m[c], a[c] * bg[c], per_backend(1e-12, kFloatTol)) << to_string(estimator) << " " << x << "," << y;
      }
    RenderResult glow = render(open);
    EXPECT_GT(pixel_mean(glow, 8, 8).x, 1.0) << to_string(estimator);
  }
}

}  // namespace pyrolume::test
