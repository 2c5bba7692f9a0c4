// CPU reference with surfaces and the environment map (issue 6, BSDF/phase
// sampling only): closed forms wherever a path's value is known exactly
// (furnaces, one bounce under a constant sky, occluders), the linearised
// texture and the lat-long orientation against independent implementations of
// the documented conventions, and a surface lit by an emissive medium.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "image/Image.h"
#include "image/ImageIo.h"
#include "render/cpu/CpuRenderer.h"
#include "render/cpu/Rng.h"
#include "render/cpu/Sampling.h"
#include "support/AnalyticScenes.h"
#include "support/Stats.h"
#include "support/SurfaceScenes.h"
#include "support/TestSupport.h"

namespace pyrolume {
namespace {

using test::pixel_mean;
using test::pixel_spread;
using test::plane_shape;
using test::pooled;
using test::srgb_to_linear;
using test::sphere_shape;
using test::TexelBytes;
using test::texture_lookup;
using test::TexVariant;
using test::write_open_box_obj;
using test::ZTestOptions;
using test::ZTestReport;

constexpr double kPi = std::numbers::pi;

RenderResult render(const Scene& s, int threads = 0) {
  RenderSettings rs;
  rs.width = s.film.width;
  rs.height = s.film.height;
  rs.spp = s.film.spp;
  rs.seed = s.film.seed;
  CpuRenderer r(threads);
  RenderResult res = r.render(s, rs, {});
  EXPECT_EQ(r.majorant_violations(), 0u);
  return res;
}



// ------------------------------------------------------------- sampler ----

// Cosine-weighted hemisphere: cos θ has density 2 cos θ (P(cos θ ≤ μ) = μ²)
// and φ is uniform; chi-square over a (cos θ, φ) grid in the frame of several
// normals, and nothing below the surface.
TEST(CpuSurfaceSampling, CosineHemisphereChiSquare) {
  const glm::dvec3 normals[] = {{0, 0, 1}, {0, 0, -1}, glm::normalize(glm::dvec3(0.3, -0.8, 0.2)), {1, 0, 0}};
  for (const glm::dvec3& n : normals) {
    glm::dvec3 t, b;
    cpu::orthonormal_basis(n, t, b);
    const int kMu = 10, kPhi = 8, N = 200000;
    std::vector<double> obs(kMu * kPhi, 0.0), expct(kMu * kPhi, 0.0);
    for (int i = 0; i < kMu; ++i)
      for (int j = 0; j < kPhi; ++j) {
        const double a = double(i) / kMu, c = double(i + 1) / kMu;
        expct[i * kPhi + j] = N * (c * c - a * a) / kPhi;
      }
    cpu::Pcg32 rng(42, 7);
    int below = 0;
    for (int k = 0; k < N; ++k) {
      cpu::BsdfSample s = cpu::sample_cosine_hemisphere(n, {rng.uniform(), rng.uniform()});
      const double mu = glm::dot(s.direction, n);
      if (mu < 0.0) ++below;
      EXPECT_NEAR(glm::length(s.direction), 1.0, 1e-12);
      EXPECT_NEAR(s.pdf, std::max(mu, 0.0) / kPi, 1e-9);
      double phi = std::atan2(glm::dot(s.direction, b), glm::dot(s.direction, t));
      if (phi < 0.0) phi += 2.0 * kPi;
      const int i = std::clamp(int(mu * kMu), 0, kMu - 1), j = std::clamp(int(phi / (2.0 * kPi) * kPhi), 0, kPhi - 1);
      obs[i * kPhi + j] += 1.0;
    }
    EXPECT_EQ(below, 0);
    test::ChiSquareResult cs = test::chi_square(obs, expct);
    EXPECT_GT(cs.p_value, 1e-4) << cs.summary();
  }
}

// ------------------------------------------------------------ furnaces ----

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

ConvexSphereCase convex_sphere_case(glm::dvec3 albedo, glm::dvec3 background, int max_depth) {
  ConvexSphereCase k;
  k.scene = test::analytic_base_scene(32, 24, 16);
  k.scene.background = background;
  k.scene.integrator.max_depth = max_depth;
  k.scene.shapes.push_back(sphere_shape(k.center, k.radius, albedo));
  return k;
}

// Classify pixels by the distance of their centre ray from the sphere's centre
// (margin ≫ the pixel footprint there, ~0.09 units): +1 fully on it, −1 fully
// off, 0 silhouette.
int classify(const ConvexSphereCase& k, int x, int y) {
  const Scene& s = k.scene;
  glm::dvec3 d = test::film_ray(s.camera, s.film.width, s.film.height, x + 0.5, y + 0.5);
  glm::dvec3 oc = k.center - s.camera.position;
  double perp = glm::length(oc - glm::dot(oc, d) * d);
  if (perp < k.radius - 0.25) return 1;
  if (perp > k.radius + 0.25) return -1;
  return 0;
}

void expect_convex_sphere(const ConvexSphereCase& k, const RenderResult& r, glm::dvec3 on, glm::dvec3 off) {
  int n_on = 0, n_off = 0;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const int cls = classify(k, x, y);
      const glm::dvec3 m = pixel_mean(r, x, y);
      if (cls == 0) {
        for (int c = 0; c < 3; ++c) {
          EXPECT_GE(m[c], std::min(on[c], off[c]) - 1e-12);
          EXPECT_LE(m[c], std::max(on[c], off[c]) + 1e-12);
        }
        continue;
      }
      const glm::dvec3 want = cls > 0 ? on : off;
      (cls > 0 ? n_on : n_off)++;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], want[c], 1e-12) << "pixel " << x << "," << y << " c " << c;
      EXPECT_LE(pixel_spread(r, x, y), 1e-12) << "pixel " << x << "," << y;
    }
  EXPECT_GT(n_on, 50);
  EXPECT_GT(n_off, 50);
  EXPECT_EQ(r.nonfinite_samples, 0u);
}

TEST(CpuSurface, FurnaceConvexSphereAlbedoOneIsOne) {
  ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(1.0), 100);
  expect_convex_sphere(k, render(k.scene), glm::dvec3(1.0), glm::dvec3(1.0));
}

TEST(CpuSurface, ConvexSphereOneBounceIsAlbedoTimesBackground) {
  const glm::dvec3 a(0.25, 0.5, 0.75), bg(0.8, 1.0, 1.2);
  for (int depth : {1, 8}) {
    ConvexSphereCase k = convex_sphere_case(a, bg, depth);
    RenderResult r = render(k.scene);
    expect_convex_sphere(k, r, a * bg, bg);
    EXPECT_GT(r.events, 0.0);
  }
}

TEST(CpuSurface, MaxDepthZeroEndsAtTheSurface) {
  ConvexSphereCase k = convex_sphere_case(glm::dvec3(1.0), glm::dvec3(1.0), 0);
  RenderResult r = render(k.scene);
  expect_convex_sphere(k, r, glm::dvec3(0.0), glm::dvec3(1.0));
  EXPECT_GT(r.events, 0.0);  // the bounce that max_depth ends still counts
}

// Every camera sample of this scene meets exactly one surface (an infinite
// plane filling the view) and escapes: events = one per camera sample.
TEST(CpuSurface, SurfaceBounceCountsAsOneEvent) {
  Scene s = test::analytic_base_scene(8, 8, 8);
  s.background = glm::dvec3(1.0);
  s.shapes.push_back(plane_shape({0, 0, 1}, {0, 0, -1}, {0, 0}, glm::dvec3(0.5)));
  RenderResult r = render(s);
  EXPECT_DOUBLE_EQ(r.events, 8.0 * 8.0 * 8.0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_NEAR(pixel_mean(r, x, y).x, 0.5, 1e-12);
}

// A concave world with inter-reflections: an open-topped box (an OBJ mesh,
// through the BVH) with a sphere standing in it and a scattering,
// non-absorbing, non-emitting medium overlapping both (rays start inside it,
// surfaces sit inside it). Albedo 1 everywhere and a white sky: every path
// that escapes returns exactly 1 (white furnace), whatever the number of
// bounces, with either estimator; with max_depth = 1 paths needing a second
// bounce die, so the image must darken (this scene does inter-reflect).

Scene concave_furnace_scene(const std::filesystem::path& obj, int max_depth) {
  Scene s = test::analytic_base_scene(24, 24, 16);
  s.camera.position = {0.6, 4.0, -2.5};
  s.camera.look_at = {0.0, -0.5, 0.0};
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = max_depth;
  Shape box;
  box.type = Shape::Type::Mesh;
  box.mesh = obj;
  box.albedo = glm::dvec3(1.0);
  s.shapes.push_back(box);
  s.shapes.push_back(sphere_shape({0.2, -0.4, 0.1}, 0.55, glm::dvec3(1.0)));
  s.media.push_back(test::homogeneous_box("fog", {-1.5, -1.5, -1.5}, {1.5, 0.5, 1.5}, glm::dvec3(0.0),
                                          {0.6, 1.0, 1.6}, 0.4, std::nullopt));
  return s;
}

TEST(CpuSurface, FurnaceConcaveMeshSphereAndMediumIsOne) {
  auto obj = write_open_box_obj(test::temp_dir("cpu_surface_furnace"));
  for (const char* estimator : {"absorption", "collision"}) {
    Scene s = concave_furnace_scene(obj, 1000);
    s.integrator.emission_estimator = estimator;
    RenderResult r = render(s);
    EXPECT_EQ(r.nonfinite_samples, 0u);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], 1.0, 1e-12) << estimator << " pixel " << x << "," << y;
      }
    EXPECT_GT(r.events / (double(r.width) * r.height * r.spp), 1.5) << "paths should bounce and scatter";
  }
  // Surface bounces and medium scatterings share max_depth: allow one event
  // and the concave box loses light.
  RenderResult shallow = render(concave_furnace_scene(obj, 1));
  double total = 0.0;
  for (double v : shallow.sum) total += v;
  EXPECT_LT(total / (double(shallow.sum.size()) * shallow.spp), 0.9);
}

// --------------------------------------------------------------- texture ----

// A textured plane under a white sky, max_depth 1: a sample that hits the
// plane bounces once and escapes, L = albedo(uv) exactly, so each pixel's mean
// is the texture averaged over the pixel footprint. The expectation uses an
// independent decode of the PNG's bytes (IEC 61966-2-1) and an independent
// bilinear/wrap lookup with the documented v flip (uv (0, 0) = the image's
// bottom-left). Wrong decoding (bytes taken as linear) or a missing flip must
// fail the same z-test.

TEST(CpuSurface, TexturedPlaneShowsLinearisedTexture) {
  const TexelBytes bytes;
  auto dir = test::temp_dir("cpu_surface_texture");
  // Linear values that encode to exactly these bytes (round(255·encode(decode(b/255))) = b).
  const auto png = test::write_texel_png(bytes, dir);

  Scene s = test::analytic_base_scene(24, 24, 128);
  s.background = glm::dvec3(1.0);
  s.integrator.max_depth = 1;
  // Plane z = 0, normal +z (facing away: the camera sees its back side), 4 × 4
  // units. SceneSurfaces: u axis = world +X projected; v axis = cross(n, u) = +Y.
  const glm::dvec3 tint(1.0, 0.9, 0.8);
  Shape plane = plane_shape({0, 0, 0}, {0, 0, 1}, {4, 4}, tint);
  plane.texture = png;
  s.shapes.push_back(plane);
  RenderResult r = render(s);
  EXPECT_EQ(r.nonfinite_samples, 0u);

  auto exact_for = [&](TexVariant v) {
    const int W = s.film.width, H = s.film.height;
    auto vals = std::make_shared<std::vector<glm::dvec3>>(size_t(W) * H);
    auto L = [&](double fx, double fy, int* sig) {
      const glm::dvec3 d = test::film_ray(s.camera, W, H, fx, fy);
      const double t = -s.camera.position.z / d.z;
      const glm::dvec3 p = s.camera.position + t * d;
      if (std::abs(p.x) > 2.0 || std::abs(p.y) > 2.0) {
        *sig = -1;
        return s.background;
      }
      return tint * texture_lookup(bytes, {p.x / 4.0 + 0.5, p.y / 4.0 + 0.5}, v, sig);
    };
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) (*vals)[size_t(y) * W + x] = test::pixel_average(L, x, y);
    return std::function<glm::dvec3(int, int)>([vals, W](int x, int y) { return (*vals)[size_t(y) * W + x]; });
  };
  ZTestReport ok = test::ztest_against_exact(r, exact_for(TexVariant::Correct), pooled());
  EXPECT_TRUE(ok.ok) << ok.summary();
  std::printf("texture: %s\n", ok.summary().c_str());
  ZTestReport no_flip = test::ztest_against_exact(r, exact_for(TexVariant::NoFlip), pooled());
  EXPECT_FALSE(no_flip.fraction_ok) << no_flip.summary();
  ZTestReport no_decode = test::ztest_against_exact(r, exact_for(TexVariant::NoDecode), pooled());
  EXPECT_FALSE(no_decode.fraction_ok) << no_decode.summary();
}

// ----------------------------------------------------------- occlusion ----

// An infinite plane between the camera and a bright emissive sphere: the
// camera sees only the plane, and the plane's bounce leaves toward the camera's
// side where there is nothing, so every sample is exactly albedo · background
// (the glow must not leak through). Without the plane the glow shows.
TEST(CpuSurface, PlaneOccludesEmissiveMedium) {
  const glm::dvec3 a(0.5, 0.25, 0.8), bg(0.2, 0.4, 0.6);
  for (const char* estimator : {"absorption", "collision"}) {
    Scene s = test::analytic_base_scene(16, 16, 16);
    s.background = bg;
    s.integrator.emission_estimator = estimator;
    s.media.push_back(test::homogeneous_sphere("glow", {0, 0, 0}, 1.0, {2, 2, 2}, {0.5, 0.5, 0.5}, 0.0,
                                               glm::dvec3(5.0, 3.0, 1.0)));
    Scene open = s;
    s.shapes.push_back(plane_shape({0, 0, -1.5}, {0, 0, 1}, {0, 0}, a));
    RenderResult r = render(s);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        const glm::dvec3 m = pixel_mean(r, x, y);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], a[c] * bg[c], 1e-12) << estimator << " " << x << "," << y;
      }
    RenderResult glow = render(open);
    EXPECT_GT(pixel_mean(glow, 8, 8).x, 1.0) << estimator;
  }
}

// A black infinite plane through the centre of an absorbing emissive sphere:
// only the half in front of the plane is seen, so with the chord ℓ clipped at
// the plane, L = Le (1 − e^{−σa ℓ}) exactly (per channel, a closed form the
// pixel quadrature integrates). The full chord must fail: media behind the
// surface do not count.
TEST(CpuSurface, SurfaceClipsMediumBehindIt) {
  const glm::dvec3 sigma_a(0.6, 1.2, 2.4), Le(1.0, 0.7, 0.4);
  const glm::dvec3 c0(0.2, 0.1, 0.0);
  const double R = 1.2;
  for (const char* estimator : {"absorption", "collision"}) {
    Scene s = test::analytic_base_scene(24, 24, 512);
    s.integrator.emission_estimator = estimator;
    s.background = glm::dvec3(3.0);  // hidden everywhere by the plane
    s.media.push_back(test::homogeneous_sphere("half", c0, R, sigma_a, glm::dvec3(0.0), 0.0, Le));
    s.shapes.push_back(plane_shape({0, 0, 0}, {0, 0, -1}, {0, 0}, glm::dvec3(0.0)));
    RenderResult r = render(s);
    EXPECT_EQ(r.nonfinite_samples, 0u);
    auto exact_for = [&](bool clip) {
      const int W = s.film.width, H = s.film.height;
      auto vals = std::make_shared<std::vector<glm::dvec3>>(size_t(W) * H);
      auto L = [&](double fx, double fy, int* sig) {
        const glm::dvec3 o = s.camera.position, d = test::film_ray(s.camera, W, H, fx, fy);
        const glm::dvec3 oc = o - c0;
        const double b = glm::dot(oc, d), disc = b * b - (glm::dot(oc, oc) - R * R);
        *sig = disc > 0.0;
        if (!(disc > 0.0)) return glm::dvec3(0.0);
        double t0 = std::max(0.0, -b - std::sqrt(disc)), t1 = -b + std::sqrt(disc);
        if (clip) t1 = std::min(t1, -o.z / d.z);
        const double len = std::max(0.0, t1 - t0);
        return Le * (glm::dvec3(1.0) - glm::exp(-sigma_a * len));
      };
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) (*vals)[size_t(y) * W + x] = test::pixel_average(L, x, y);
      return std::function<glm::dvec3(int, int)>([vals, W](int x, int y) { return (*vals)[size_t(y) * W + x]; });
    };
    ZTestReport ok = test::ztest_against_exact(r, exact_for(true), pooled());
    EXPECT_TRUE(ok.ok) << estimator << ": " << ok.summary();
    std::printf("%s clipped: %s\n", estimator, ok.summary().c_str());
    ZTestReport full = test::ztest_against_exact(r, exact_for(false), pooled());
    EXPECT_FALSE(full.ok) << estimator << ": " << full.summary();
  }
}

// ---------------------------------------------------- lit by the medium ----

// A homogeneous emissive, scattering sphere above a white diffuse plane, black
// sky: the plane is lit only through BSDF-sampled paths that find the sphere.
// Plane pixels must be > 0 and finite, and both emission estimators must
// converge to the same image.
Scene lit_plane_scene(const char* estimator, uint32_t seed) {
  Scene s = test::analytic_base_scene(20, 16, 96);
  s.film.seed = seed;
  s.camera.position = {0, 1.5, -5};
  s.camera.look_at = {0, -0.3, 0};
  s.integrator.emission_estimator = estimator;
  s.integrator.max_depth = 6;
  s.media.push_back(test::homogeneous_sphere("fire", {0, 0.4, 0}, 0.8, {1.5, 1.5, 1.5}, {0.5, 0.5, 0.5}, 0.3,
                                             glm::dvec3(4.0, 2.0, 0.8)));
  s.shapes.push_back(plane_shape({0, -0.6, 0}, {0, 1, 0}, {0, 0}, glm::dvec3(0.8)));
  return s;
}

TEST(CpuSurface, EmissiveSphereLightsPlane) {
  Scene s = lit_plane_scene("collision", 3);
  RenderResult r = render(s);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  for (double v : r.sum) ASSERT_TRUE(std::isfinite(v));
  // Bottom rows: the plane in front of the sphere (no medium on the camera ray).
  double near_sum = 0.0;
  for (int x = 0; x < r.width; ++x) near_sum += pixel_mean(r, x, r.height - 1).x;
  EXPECT_GT(near_sum / r.width, 0.0);

  ZTestReport same = test::ztest_images(render(lit_plane_scene("absorption", 4)), r, pooled(0.03));
  EXPECT_TRUE(same.ok) << same.summary();
  std::printf("absorption vs collision: %s\n", same.summary().c_str());
}

TEST(CpuSurface, DeterministicAcrossThreadCounts) {
  Scene s = lit_plane_scene("absorption", 9);
  s.film.spp = 8;
  RenderResult a = render(s, 1), b = render(s, 3);
  EXPECT_EQ(a.sum, b.sum);
  EXPECT_EQ(a.sum_sq, b.sum_sq);
  EXPECT_EQ(a.events, b.events);
}

// ---------------------------------------------------------- environment ----

// The documented lat-long convention (EnvironmentMap.h, Blender's), written
// here independently: +Z up, θ from +Z, φ = atan2(y, x), u = (π − φ)/(2π),
// v = θ/π (row 0 = top = +Z); rotation_deg turns the map about +Z, so a
// direction d sees the unrotated map at Rz(−rotation)·d; bilinear between
// texel centres, wrapping in u, clamping in v; × scale.
struct EnvTexels {
  int w = 8, h = 4;
  std::vector<float> rgb;
  EnvTexels() {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        rgb.push_back(0.1f + 0.3f * x);                      // r grows with u
        rgb.push_back(2.0f - 0.5f * y);                      // g: bright at the top
        rgb.push_back((x + 2 * y) % 3 == 0 ? 1.5f : 0.25f);  // b: a pattern
      }
  }
};

glm::dvec3 env_radiance(const EnvTexels& e, glm::dvec3 d, double scale, double rot_deg, int* sig) {
  d = glm::normalize(d);
  const double r = rot_deg * kPi / 180.0;
  const double x = std::cos(r) * d.x + std::sin(r) * d.y, y = -std::sin(r) * d.x + std::cos(r) * d.y;
  double u = (kPi - std::atan2(y, x)) / (2.0 * kPi);
  u -= std::floor(u);
  const double v = std::acos(std::clamp(d.z, -1.0, 1.0)) / kPi;
  const double X = u * e.w - 0.5, Y = v * e.h - 0.5;
  const double x0 = std::floor(X), y0 = std::floor(Y), fx = X - x0, fy = Y - y0;
  if (sig) *sig = int(x0) * 1000 + int(y0);
  auto texel = [&](int i, int j) {
    i = ((i % e.w) + e.w) % e.w;
    j = std::clamp(j, 0, e.h - 1);
    const size_t k = (size_t(j) * e.w + i) * 3;
    return glm::dvec3(e.rgb[k], e.rgb[k + 1], e.rgb[k + 2]);
  };
  const int i = int(x0), j = int(y0);
  return scale * ((1 - fy) * ((1 - fx) * texel(i, j) + fx * texel(i + 1, j)) +
                  fy * ((1 - fx) * texel(i, j + 1) + fx * texel(i + 1, j + 1)));
}

TEST(CpuSurface, EnvironmentMapSeenByCameraRays) {
  const EnvTexels env;
  auto dir = test::temp_dir("cpu_surface_env");
  Image img = make_image(env.w, env.h);
  img.rgb = env.rgb;
  const auto exr = dir / "sky.exr";
  write_image(exr, img);

  const double scale = 1.5, rot = 30.0;
  Scene s = test::analytic_base_scene(32, 20, 32);
  s.camera.position = {0, 0, 0};
  s.camera.look_at = {1.0, 0.4, 0.3};
  s.camera.up = {0, 0, 1};
  s.camera.fov_deg = 100.0;
  s.background = glm::dvec3(7.0);  // must not be seen
  s.environment = Environment{exr, scale, rot};
  RenderResult r = render(s);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  EXPECT_EQ(r.events, 0.0);

  auto exact_for = [&](double rotation, bool mirror_u) {
    const int W = s.film.width, H = s.film.height;
    auto vals = std::make_shared<std::vector<glm::dvec3>>(size_t(W) * H);
    auto L = [&](double fx, double fy, int* sig) {
      glm::dvec3 d = test::film_ray(s.camera, W, H, fx, fy);
      if (mirror_u) d.y = -d.y;  // u growing counter-clockwise instead
      return env_radiance(env, d, scale, rotation, sig);
    };
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) (*vals)[size_t(y) * W + x] = test::pixel_average(L, x, y);
    return std::function<glm::dvec3(int, int)>([vals, W](int x, int y) { return (*vals)[size_t(y) * W + x]; });
  };
  ZTestReport ok = test::ztest_against_exact(r, exact_for(rot, false), pooled());
  EXPECT_TRUE(ok.ok) << ok.summary();
  std::printf("environment: %s\n", ok.summary().c_str());
  ZTestReport unrotated = test::ztest_against_exact(r, exact_for(0.0, false), pooled());
  EXPECT_FALSE(unrotated.fraction_ok) << unrotated.summary();
  ZTestReport mirrored = test::ztest_against_exact(r, exact_for(rot, true), pooled());
  EXPECT_FALSE(mirrored.fraction_ok) << mirrored.summary();
}

// Scattered rays see the environment too (not background.rgb): a uniform map
// around the convex sphere gives albedo · scale · value on it, exactly, by
// BSDF sampling alone (light sampling the map would add noise to the exact
// value, so it is turned off).
TEST(CpuSurface, EnvironmentMapSeenByScatteredRays) {
  auto dir = test::temp_dir("cpu_surface_env_uniform");
  Image img = make_image(4, 2);
  for (size_t p = 0; p < img.pixel_count(); ++p) {
    img.rgb[p * 3 + 0] = 0.25f;  // exact in float and half
    img.rgb[p * 3 + 1] = 0.5f;
    img.rgb[p * 3 + 2] = 0.75f;
  }
  const auto exr = dir / "uniform.exr";
  write_image(exr, img);
  const glm::dvec3 a(0.5, 0.8, 1.0), sky = 2.0 * glm::dvec3(0.25, 0.5, 0.75);
  ConvexSphereCase k = convex_sphere_case(a, glm::dvec3(9.0), 4);
  k.scene.environment = Environment{exr, 2.0, 45.0};
  k.scene.integrator.mis = false;
  expect_convex_sphere(k, render(k.scene), a * sky, sky);
}

}  // namespace
}  // namespace pyrolume
