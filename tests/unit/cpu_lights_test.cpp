// The scene's analytic lights in the CPU reference (docs/lights.md "Analytic
// lights"): a diffuse plane under a point light, a delta sun, a disc sun, a
// spot and a sphere light against closed forms computed here (own camera
// model, own ray tests, own smoothstep); shadows from surfaces and sphere
// lights; camera rays that see a disc sun or a sphere light, through a medium
// too; light rays toward delta lights that are attenuated by a medium but
// collect nothing; single scattering of a point light in a medium; and every
// light together under a sky with each light strategy.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/cpu/CpuRenderer.h"
#include "support/AnalyticScenes.h"
#include "support/LightScenes.h"
#include "support/MisScenes.h"
#include "support/Stats.h"
#include "support/SurfaceScenes.h"
#include "util/Math.h"

namespace pyrolume {
namespace {

using test::ZTestOptions;
using test::ZTestReport;

constexpr double kInf = std::numeric_limits<double>::infinity();
const glm::dvec3 kAlbedo(0.8, 0.6, 0.4);  // the plane's
const glm::dvec3 kUp(0, 1, 0);            // the plane's normal

RenderResult render_lights(const Scene& s, const char* strategy = "mis") {
  CpuRenderer r(0);
  RenderResult res = r.render(s, test::settings_for(s), {});
  EXPECT_EQ(r.majorant_violations(), 0u);
  EXPECT_EQ(res.nonfinite_samples, 0u);
  if (strategy) EXPECT_EQ(res.light_strategy, strategy);
  return res;
}

using test::distant_light;
using test::point_light;
using test::sphere_light;
using test::spot_light;

// --------------------------------------------------------- closed forms ----

// Nearest t > t_min where the ray o + t·d (unit d) meets the sphere's
// surface (from outside: the near side), or ∞.
double hit_sphere(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& c, double r, double t_min = 0.0) {
  const glm::dvec3 oc = o - c;
  const double b = glm::dot(oc, d), q = glm::dot(oc, oc) - r * r;
  const double disc = b * b - q;
  if (disc <= 0.0) return kInf;
  const double s = std::sqrt(disc);
  if (-b - s > t_min) return -b - s;
  return -b + s > t_min ? -b + s : kInf;
}

// Whether the segment from x to x + t·d, t < t_max, meets any of the spheres
// (x may lie on one of them).
bool blocked(const glm::dvec3& x, const glm::dvec3& d, double t_max, const std::vector<glm::dvec4>& spheres) {
  for (const glm::dvec4& s : spheres)
    if (hit_sphere(x, d, glm::dvec3(s), s.w, 1e-9) < t_max) return true;
  return false;
}

// pbrt-v4's spot falloff: smoothstep from cos(cone) (0) to cos(cone − falloff) (1).
double spot_factor(const Light& l, double cos_alpha) {
  const double lo = std::cos(l.cone_deg * kPi / 180.0), hi = std::cos((l.cone_deg - l.falloff_deg) * kPi / 180.0);
  if (cos_alpha >= hi) return 1.0;
  if (cos_alpha < lo) return 0.0;
  const double t = (cos_alpha - lo) / (hi - lo);
  return t * t * (3.0 - 2.0 * t);
}

// Irradiance at point x (normal n) from a point or spot light, a delta sun or
// a sphere light (the sphere wholly above x's horizon: E = π L (r/D)² cos θ,
// docs/lights.md), unless one of the occluders blocks a delta light. A disc
// sun: E cos θ (its cone wholly above the horizon). `sig` grows where a delta
// light is blocked.
glm::dvec3 irradiance(const Light& l, const glm::dvec3& x, const glm::dvec3& n,
                      const std::vector<glm::dvec4>& occluders, int* sig) {
  const glm::dvec3 value = l.scale * *l.rgb;
  switch (l.type) {
    case Light::Type::Distant: {
      if (l.angle_deg == 0.0 && blocked(x, l.direction, kInf, occluders)) {
        *sig += 1;
        return glm::dvec3(0.0);
      }
      return value * std::max(0.0, glm::dot(n, l.direction));
    }
    case Light::Type::Point:
    case Light::Type::Spot: {
      const glm::dvec3 v = l.position - x;
      const double r = glm::length(v);
      const glm::dvec3 w = v / r;
      if (blocked(x, w, r, occluders)) {
        *sig += 1;
        return glm::dvec3(0.0);
      }
      const double f = l.type == Light::Type::Spot ? spot_factor(l, -glm::dot(l.direction, w)) : 1.0;
      if (l.type == Light::Type::Spot) *sig += f == 0.0 ? 2 : f == 1.0 ? 4 : 8;  // refine at the cone's edges
      return value * (f * std::max(0.0, glm::dot(n, w)) / (r * r));
    }
    case Light::Type::Sphere: {
      const glm::dvec3 v = l.center - x;
      const double D2 = glm::dot(v, v);
      return value * (kPi * l.radius * l.radius / D2 * std::max(0.0, glm::dot(n, v) / std::sqrt(D2)));
    }
  }
  return glm::dvec3(0.0);
}

// The spheres that block delta lights: the scene's sphere shapes and sphere lights.
std::vector<glm::dvec4> occluders_of(const Scene& s) {
  std::vector<glm::dvec4> o;
  for (const Shape& sh : s.shapes)
    if (sh.type == Shape::Type::Sphere) o.push_back(glm::dvec4(sh.center, sh.radius));
  for (const Light& l : s.lights)
    if (l.type == Light::Type::Sphere) o.push_back(glm::dvec4(l.center, l.radius));
  return o;
}

// The plane y = 0 (albedo kAlbedo), seen straight from above, lit only by
// the scene's lights; max_depth 1: what reaches the camera is the direct
// light reflected once.
Scene plane_scene(int spp) {
  Scene s = test::analytic_base_scene(16, 16, spp);
  s.camera.position = {0, 4, 0};
  s.camera.look_at = {0, 0, 0};
  s.camera.up = {0, 0, 1};
  s.integrator.max_depth = 1;
  s.shapes.push_back(test::plane_shape({0, 0, 0}, kUp, {0, 0}, kAlbedo));
  return s;
}

// Expected pixel means of a plane_scene with sphere shapes (albedo ρ_k, lit
// the same way, normal outward) and lights: a camera ray that meets a sphere
// light first sees its radiance; a surface point x reflects ρ/π · Σ E(x) +
// ρ · L_sky (a uniform sky of radiance L_sky seen through whatever sphere
// lights cover it: their cones replace it, E_sky = π L_sky − Σ π L_sky (r/D)² cos θ).
std::function<glm::dvec3(int, int)> expected_image(const Scene& s, glm::dvec3 sky = glm::dvec3(0.0)) {
  const std::vector<glm::dvec4> occ = occluders_of(s);
  return test::exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
    const glm::dvec3 o = s.camera.position, d = test::film_ray(s.camera, s.film.width, s.film.height, fx, fy);
    *sig = 0;
    double t_best = d.y < 0.0 ? -o.y / d.y : kInf;  // the plane
    const Light* light = nullptr;
    const Shape* shape = nullptr;
    for (const Light& l : s.lights) {
      const double t = l.type == Light::Type::Sphere ? hit_sphere(o, d, l.center, l.radius) : kInf;
      if (t < t_best) t_best = t, light = &l, shape = nullptr;
    }
    for (const Shape& sh : s.shapes) {
      const double t = sh.type == Shape::Type::Sphere ? hit_sphere(o, d, sh.center, sh.radius) : kInf;
      if (t < t_best) t_best = t, shape = &sh, light = nullptr;
    }
    if (light) {
      *sig = -1;
      return light->scale * *light->rgb;
    }
    if (t_best == kInf) {
      *sig = -2;
      return glm::dvec3(0.0);
    }
    const glm::dvec3 x = o + t_best * d;
    const glm::dvec3 n = shape ? glm::normalize(x - shape->center) : kUp;
    const glm::dvec3 albedo = shape ? shape->albedo : kAlbedo;
    *sig = shape ? 1 : 0;  // then 4 bits per light
    glm::dvec3 E = kPi * sky;
    for (const Light& l : s.lights) {
      int k = 0;
      E += irradiance(l, x, n, occ, &k);
      *sig = (*sig << 4) + k;
      if (l.type == Light::Type::Sphere) E -= irradiance(sphere_light(l.center, l.radius, sky), x, n, occ, &k);
    }
    return albedo / kPi * E;
  });
}

// Pixel-channel z-tests against the closed form; pooled 3×3 (few spp) or not.
void expect_matches(const RenderResult& r, const std::function<glm::dvec3(int, int)>& exact, double tolerance,
                    bool pooled, const char* what) {
  ZTestOptions o;
  o.pool3x3 = pooled;
  o.bias_tolerance = tolerance;
  const ZTestReport z = test::ztest_against_exact(r, exact, o);
  EXPECT_TRUE(z.ok) << what << ": " << z.summary();
  std::printf("%s: %s\n", what, z.summary().c_str());
}

glm::dvec3 pixel_sum(const RenderResult& r, int x, int y) {
  const size_t p = (size_t(y) * r.width + x) * 3;
  return {r.sum[p], r.sum[p + 1], r.sum[p + 2]};
}

// ------------------------------------------------------------------- tests ----

// L = ρ/π · I cos θ / r² (docs/lights.md): every sample of a pixel differs
// only by where it falls in the pixel, so the pixel means are tight.
TEST(CpuLights, PointLightOnPlane) {
  Scene s = plane_scene(64);
  s.lights.push_back(point_light({0.4, 1.5, -0.3}, {2, 3, 4}));
  expect_matches(render_lights(s), expected_image(s), 0.005, false, "point light");
}

// L = ρ/π · E cos θ, the same for every sample of every pixel.
TEST(CpuLights, DeltaSunOnPlane) {
  Scene s = plane_scene(64);
  s.lights.push_back(distant_light({0.3, 1, -0.4}, {1.5, 2, 2.5}, 0.0));
  const RenderResult r = render_lights(s);
  expect_matches(r, expected_image(s), 0.005, false, "delta sun");
  const glm::dvec3 L = kAlbedo / kPi * glm::dvec3(1.5, 2, 2.5) * s.lights[0].direction.y;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(pixel_sum(r, 7, 9)[c] / r.spp, L[c], 1e-12 * L[c]);
}

// A sphere light over the plane: π L (r/D)² cos θ
// (exact while the sphere is above the horizon). The BSDF's rays that hit it
// and the light's cone samples are combined by MIS.
TEST(CpuLights, SphereLightOnPlane) {
  Scene s = plane_scene(256);
  s.lights.push_back(sphere_light({1.6, 1.2, -0.2}, 0.3, {3, 2, 1}));  // just outside the view
  expect_matches(render_lights(s), expected_image(s), 0.005, true, "sphere light");
}

// On the light's axis, a plane facing it at distance d receives
// E = π L (r/d)² (docs/lights.md): a camera with a 0.1° field of view looks
// at that point from the side, and every sample estimates ρ/π · E.
TEST(CpuLights, SphereLightOnAxis) {
  Scene s = plane_scene(1024);
  s.film.width = s.film.height = 4;
  const double d = 1.2, r = 0.3;
  const glm::dvec3 L(3, 2, 1), axis_point(0.3, 0, -0.2);
  s.lights.push_back(sphere_light(axis_point + glm::dvec3(0, d, 0), r, L));
  s.camera.position = axis_point + glm::dvec3(0, 2.5, -3);
  s.camera.look_at = axis_point;
  s.camera.up = {0, 1, 0};
  s.camera.fov_deg = 0.1;
  const RenderResult res = render_lights(s);
  const glm::dvec3 expected = kAlbedo / kPi * (kPi * L * (r * r / (d * d)));
  const double n = double(res.spp) * 16;
  for (int c = 0; c < 3; ++c) {
    double sum = 0.0, sum_sq = 0.0;
    for (size_t p = 0; p < 16; ++p) sum += res.sum[p * 3 + c], sum_sq += res.sum_sq[p * 3 + c];
    const double mean = sum / n, se = std::sqrt((sum_sq / n - mean * mean) / (n - 1));
    EXPECT_NEAR(mean, expected[c], 4.0 * se) << "channel " << c;
    EXPECT_LT(se, 0.01 * expected[c]) << "channel " << c;  // informative
    std::printf("on the axis, channel %d: %.6f vs %.6f, SE %.2g\n", c, mean, expected[c], se);
  }
}

// A disc sun and a delta sun of the same irradiance light a plane alike
// (E = π L sin²θ: docs/lights.md), for a wide disc, where MIS matters, and
// for the real sun's 0.53°, where 1 − cos θ ≈ 1e-5.
TEST(CpuLights, DiscSunMatchesDeltaSun) {
  Scene delta = plane_scene(64);
  delta.lights.push_back(distant_light({0.3, 1, -0.2}, {2, 1.5, 1}, 0.0));
  const RenderResult rd = render_lights(delta);
  for (double angle : {20.0, 0.53}) {
    Scene disc = delta;
    disc.lights[0].angle_deg = angle;
    const RenderResult r = render_lights(disc);
    const std::string what = "disc sun " + std::to_string(angle) + " deg";
    expect_matches(r, expected_image(delta), 0.005, true, (what + " vs closed form").c_str());
    ZTestOptions o;
    o.pool3x3 = true;
    const ZTestReport z = test::ztest_images(r, rd, o);
    EXPECT_TRUE(z.ok) << what << " vs delta sun: " << z.summary();
    std::printf("%s vs delta sun: %s\n", what.c_str(), z.summary().c_str());
  }
}

// A spot: inside cone_deg − falloff_deg a point light (the same samples),
// beyond cone_deg dark, between them pbrt-v4's smoothstep.
TEST(CpuLights, SpotIsPointLightInsideAndDarkOutside) {
  Scene point = plane_scene(256);
  point.lights.push_back(point_light({0.2, 1.5, 0.1}, {3, 2, 1}));
  Scene spot = point;
  spot.lights[0] = spot_light({0.2, 1.5, 0.1}, {0.15, -1, 0.05}, {3, 2, 1}, 30.0, 10.0);
  const RenderResult rp = render_lights(point), rs = render_lights(spot);
  expect_matches(rs, expected_image(spot), 0.005, true, "spot");
  // Angles from the spot's axis over a 9 × 9 grid of each pixel's footprint.
  int inside = 0, outside = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      double lo = 180.0, hi = 0.0;
      for (int j = 0; j <= 8; ++j)
        for (int i = 0; i <= 8; ++i) {
          const glm::dvec3 d = test::film_ray(spot.camera, 16, 16, x + i / 8.0, y + j / 8.0);
          const glm::dvec3 p = spot.camera.position + (-spot.camera.position.y / d.y) * d;
          const double a =
              std::acos(glm::dot(spot.lights[0].direction, glm::normalize(p - spot.lights[0].position))) * 180 / kPi;
          lo = std::min(lo, a);
          hi = std::max(hi, a);
        }
      if (hi < 19.0) {
        ++inside;
        EXPECT_EQ(pixel_sum(rs, x, y), pixel_sum(rp, x, y)) << "pixel " << x << ", " << y << " inside the inner cone";
      } else if (lo > 31.0) {
        ++outside;
        EXPECT_EQ(pixel_sum(rs, x, y), glm::dvec3(0.0)) << "pixel " << x << ", " << y << " outside the cone";
      }
    }
  EXPECT_GT(inside, 10);
  EXPECT_GT(outside, 10);
}

// A diffuse sphere between a point light and the plane: the plane in its
// shadow is dark (max_depth 1), the sphere's top lit.
TEST(CpuLights, SurfaceBlocksPointLight) {
  Scene s = plane_scene(64);
  s.lights.push_back(point_light({0.3, 2.0, -0.2}, {4, 3, 2}));
  s.shapes.push_back(test::sphere_shape({0.5, 0.9, 0.1}, 0.3, glm::dvec3(0.5, 0.7, 0.9)));
  expect_matches(render_lights(s), expected_image(s), 0.005, true, "point light, sphere's shadow");
}

// A sphere light blocks a delta sun (opaque) and lights the plane beside it;
// the two are chosen 1/2 each (docs/lights.md "Choosing a light").
TEST(CpuLights, SphereLightBlocksSun) {
  Scene s = plane_scene(256);
  // The sphere just outside the view, its shadow in it.
  s.lights.push_back(distant_light({1.1, 1.2, -0.2}, {1, 1.2, 1.4}, 0.0));
  s.lights.push_back(sphere_light({1.6, 1.2, -0.2}, 0.35, {2, 1.5, 1}));
  expect_matches(render_lights(s), expected_image(s), 0.005, true, "sun and sphere light");
}

// Camera rays that escape inside a disc sun's cone see its radiance
// E / (π sin²θ) on top of the background.
TEST(CpuLights, CameraSeesDiscSun) {
  Scene s = test::analytic_base_scene(16, 16, 256);
  const glm::dvec3 a = glm::normalize(glm::dvec3(0.2, 1, 0.3));
  s.camera.position = {0, 0, 0};
  s.camera.look_at = a;
  s.camera.up = {0, 0, 1};
  s.camera.fov_deg = 10.0;
  s.background = {0.1, 0.2, 0.3};
  s.lights.push_back(distant_light(a, {1, 2, 3}, 5.0));
  const double theta = 2.5 * kPi / 180.0;
  const glm::dvec3 L = glm::dvec3(1, 2, 3) / (kPi * std::sin(theta) * std::sin(theta));
  const auto exact = test::exact_image(16, 16, [&](double fx, double fy, int* sig) {
    const bool in = glm::dot(test::film_ray(s.camera, 16, 16, fx, fy), a) >= std::cos(theta);
    *sig = in;
    return s.background + (in ? L : glm::dvec3(0.0));
  });
  expect_matches(render_lights(s, "bsdf"), exact, 0.005, false, "disc sun seen by the camera");
}

// A sphere light behind an absorbing slab: camera rays are tracked up to it
// and see L·exp(−σa ℓ); the background around it the same way. From inside a
// sphere light nothing is seen (it emits outward only, and is opaque).
TEST(CpuLights, CameraSeesSphereLightThroughMedium) {
  Scene s = test::analytic_base_scene(16, 16, 256);
  s.background = {0.5, 0.5, 0.5};
  const glm::dvec3 sigma(0.3, 0.6, 0.9), Ls(2, 3, 4);
  s.media.push_back(test::homogeneous_box("slab", {-10, -10, -2.5}, {10, 10, -1.5}, sigma, glm::dvec3(0.0), 0.0,
                                          std::nullopt));
  s.lights.push_back(sphere_light({0, 0, 0}, 0.6, Ls));
  const auto exact = test::exact_image(16, 16, [&](double fx, double fy, int* sig) {
    const glm::dvec3 d = test::film_ray(s.camera, 16, 16, fx, fy);
    const bool in = hit_sphere(s.camera.position, d, glm::dvec3(0.0), 0.6) < kInf;
    *sig = in;
    const glm::dvec3 T = glm::exp(-sigma / std::abs(d.z));
    return T * (in ? Ls : s.background);
  });
  expect_matches(render_lights(s, "bsdf"), exact, 0.01, false, "sphere light through a slab");

  Scene inside = s;
  inside.media.clear();
  inside.lights[0].radius = 6.0;  // the camera is 5 from its centre
  const RenderResult r = render_lights(inside, "bsdf");
  for (double v : r.sum) EXPECT_EQ(v, 0.0);
}

// A point light above an emissive absorbing slab, the plane below it, the
// camera between: the light ray toward the point light is attenuated by
// exp(−σa h/cos) and collects none of the slab's emission, which reaches the
// plane by the BSDF's rays only: E_slab = 2π Le ∫₀¹ (1 − e^{−σa h/μ}) μ dμ.
TEST(CpuLights, DeltaLightRayIsAttenuatedAndCollectsNothing) {
  Scene s = plane_scene(256);
  s.camera.position = {0, 0.45, 0};
  s.camera.fov_deg = 60.0;
  const glm::dvec3 sigma(0.5, 1.0, 1.5), Le(1.0, 0.5, 0.25), I(2, 2, 2);
  const double h = 0.5;
  s.media.push_back(test::homogeneous_box("slab", {-1000, 0.5, -1000}, {1000, 0.5 + h, 1000}, sigma,
                                          glm::dvec3(0.0), 0.0, Le));
  s.lights.push_back(point_light({0.1, 2.0, 0.2}, I));
  glm::dvec3 E_slab(0.0);
  const int N = 4000;  // midpoint rule over μ ∈ (0, 1]
  for (int k = 0; k < N; ++k) {
    const double mu = (k + 0.5) / N;
    E_slab += (1.0 - glm::exp(-sigma * h / mu)) * mu / double(N);
  }
  E_slab *= 2.0 * kPi * Le;
  const auto exact = test::exact_image(16, 16, [&](double fx, double fy, int* sig) {
    const glm::dvec3 d = test::film_ray(s.camera, 16, 16, fx, fy);
    const glm::dvec3 x = s.camera.position + (-s.camera.position.y / d.y) * d;
    const glm::dvec3 v = s.lights[0].position - x;
    const double r = glm::length(v), cos_t = v.y / r;
    *sig = 0;
    return kAlbedo / kPi * (I * cos_t / (r * r) * glm::exp(-sigma * h / cos_t) + E_slab);
  });
  expect_matches(render_lights(s), exact, 0.01, true, "point light through an emissive slab");
}

// Single scattering of a point light in a homogeneous HG medium (max_depth 1):
// L = ∫ e^{−σt (t − t0)} σs p(cos) I/r² e^{−σt ℓ(t)} dt along the camera ray,
// ℓ the light ray's length inside the sphere; delta light rays from medium
// vertices.
TEST(CpuLights, PointLightSingleScattering) {
  Scene s = test::analytic_base_scene(16, 16, 1024);
  s.integrator.max_depth = 1;
  const glm::dvec3 sigma_a(0.3), sigma_s(0.6, 0.4, 0.2), I(4, 4, 4);
  const double g = 0.3, R = 1.0;
  s.media.push_back(test::homogeneous_sphere("smoke", {0, 0, 0}, R, sigma_a, sigma_s, g, std::nullopt));
  s.lights.push_back(point_light({1.6, 1.2, -0.8}, I));
  const glm::dvec3 p = s.lights[0].position;
  auto L_ray = [&](double fx, double fy, int* sig) {
    const glm::dvec3 o = s.camera.position, d = test::film_ray(s.camera, 16, 16, fx, fy);
    const double b = glm::dot(o, d), disc = b * b - (glm::dot(o, o) - R * R);
    *sig = disc > 0.0;
    if (!(disc > 0.0)) return glm::dvec3(0.0);
    const double t0 = -b - std::sqrt(disc), t1 = -b + std::sqrt(disc);
    glm::dvec3 L(0.0);
    const int N = 64;  // midpoint rule
    for (int k = 0; k < N; ++k) {
      const double t = t0 + (k + 0.5) * (t1 - t0) / N;
      const glm::dvec3 x = o + t * d;
      const glm::dvec3 v = p - x;
      const double r = glm::length(v);
      const glm::dvec3 w = v / r;
      const double ell = -glm::dot(x, w) + std::sqrt(glm::dot(x, w) * glm::dot(x, w) - (glm::dot(x, x) - R * R));
      const double cos_t = glm::dot(d, w), den = 1.0 + g * g - 2.0 * g * cos_t;
      const double phase = (1.0 - g * g) / (4.0 * kPi * den * std::sqrt(den));
      const glm::dvec3 sigma_t = sigma_a + sigma_s;
      L += glm::exp(-sigma_t * (t - t0 + ell)) * sigma_s * (phase / (r * r)) * I;
    }
    return L * ((t1 - t0) / N);
  };
  // The integrand is smooth inside the silhouette: refine only across it.
  std::vector<glm::dvec3> means(16 * 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) means[y * 16 + x] = test::pixel_average(L_ray, x, y, 8, 3, 1e9);
  expect_matches(render_lights(s), [&](int x, int y) { return means[y * 16 + x]; }, 0.01, true,
                 "point light, single scattering");
}

// Every kind of light at once under a uniform sky (docs/lights.md "Choosing a
// light": sky and disc sun share one half by power, the rest the other), with
// MIS, several light samples and the ratio-tracked continuation, guided
// continuations (which end on a delta light's pick), and light sampling only.
TEST(CpuLights, EveryLightUnderSkyWithEachStrategy) {
  const auto dir = test::temp_dir("cpu_lights_sky");
  const glm::dvec3 sky(0.2, 0.25, 0.3);
  Scene s = plane_scene(128);
  s.environment = Environment{test::write_uniform_sky(dir, glm::vec3(sky)), 1.0, 0.0};
  s.lights.push_back(point_light({-0.5, 1.8, -0.4}, {1, 1.5, 2}));
  s.lights.push_back(spot_light({0.4, 1.6, 0.6}, {0.2, -1, -0.3}, {3, 2, 1}, 35.0, 15.0));
  // Its shadow from the sphere light falls outside the image (checked below).
  s.lights.push_back(distant_light({-0.8, 1, 0}, {1.2, 1, 0.8}, 10.0));
  s.lights.push_back(sphere_light({1.5, 1.5, 0.3}, 0.25, {4, 3, 2}));  // just outside the view
  s.lights.push_back(distant_light({0.2, 1, 0.5}, {0.3, 0.3, 0.3}, 0.0));
  // The disc sun's cone never meets the sphere light from the plane in view.
  for (int y = 0; y <= 16; ++y)
    for (int x = 0; x <= 16; ++x) {
      const glm::dvec3 d = test::film_ray(s.camera, 16, 16, x, y);
      const glm::dvec3 p = s.camera.position + (-s.camera.position.y / d.y) * d;
      const glm::dvec3 v = s.lights[3].center - p;
      const double apart = std::acos(glm::dot(glm::normalize(v), s.lights[2].direction));
      ASSERT_GT(apart, std::asin(0.25 / glm::length(v)) + 5.0 * kPi / 180.0) << "the disc sun's shadow is in view";
    }
  const auto exact = expected_image(s, sky);
  struct Case {
    const char* what;
    bool light_only;
    int light_samples;
    bool ratio;
    double guided;
  };
  for (const Case& c : {Case{"MIS", false, 1, false, 0.0}, Case{"MIS, 3 light samples, ratio-tracked", false, 3, true, 0.0},
                        Case{"MIS, guided 0.5", false, 1, false, 0.5}, Case{"light only", true, 1, false, 0.0}}) {
    Scene t = s;
    t.integrator.light_only = c.light_only;
    t.integrator.surface_light_samples = c.light_samples;
    t.integrator.ratio_tracked_continuation = c.ratio;
    if (c.guided > 0.0) t.integrator.guided_continuation = c.guided;
    expect_matches(render_lights(t, c.light_only ? "light_only" : "mis"), exact, 0.01, true, c.what);
  }
}

}  // namespace
}  // namespace pyrolume
