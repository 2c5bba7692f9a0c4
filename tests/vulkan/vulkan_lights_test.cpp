// The scene's analytic lights on the Vulkan backend (docs/lights.md
// "Analytic lights"), validation layers on: a Lambertian plane under each
// kind of light against its closed form, per pixel (z-tests with the
// render's own standard errors, docs/testing.md):
//   point:    L = ρ/π · I cos θ / r²
//   spot:     the point light times the smoothstep falloff; 0 outside the cone
//   distant:  L = ρ/π · E cos θ, the delta light and the disc sun alike (over
//             a cone fully above the horizon ∫ L cos dω = π L sin²θ · cos θ_axis)
//   sphere:   a sphere of radiance L fully above the plane gives
//             E = π L r² cos θ / d² (E = π L (r/d)² on its axis), and camera
//             rays that hit it see L.
// Each test also checks that a wrong closed form is rejected, so the z-test
// has the power to see a factor of 1.1.
#include <cmath>
#include <functional>
#include <numbers>

#include <gtest/gtest.h>

#include "render/cpu/CpuRenderer.h"
#include "scene/Scene.h"
#include "support/AnalyticScenes.h"
#include "support/LightScenes.h"
#include "support/MisScenes.h"
#include "support/Stats.h"
#include "support/SurfaceScenes.h"
#include "support/VulkanFixture.h"

namespace pyrolume {
namespace {

using test::ZTestOptions;
using test::ZTestReport;
constexpr double kPi = std::numbers::pi;
constexpr double kAlbedo = 0.6;

// A plane y = 0 (unbounded, albedo kAlbedo) seen obliquely from above.
Scene lit_plane_scene(int spp) {
  Scene s = test::analytic_base_scene(20, 20, spp);
  s.camera.position = {0, 3, -4};
  s.camera.look_at = {0, 0, 0.5};
  s.shapes.push_back(test::plane_shape({0, 0, 0}, {0, 1, 0}, {0, 0}, glm::dvec3(kAlbedo)));
  return s;
}

// Pixel means of ρ/π · E(p) over the plane, E given per plane point; `sky`
// for rays that miss the plane, `seen` for what the camera may see before it
// (a sphere light) with its own signature.
std::function<glm::dvec3(int, int)> plane_exact(const Scene& s, const std::function<double(glm::dvec3, int*)>& E,
                                                const std::function<bool(glm::dvec3, glm::dvec3, glm::dvec3*)>& seen = {}) {
  return test::exact_image(s.film.width, s.film.height, [&s, E, seen](double fx, double fy, int* sig) {
    const glm::dvec3 o = s.camera.position, d = test::film_ray(s.camera, s.film.width, s.film.height, fx, fy);
    glm::dvec3 L;
    if (seen && seen(o, d, &L)) {
      *sig = 7;
      return L;
    }
    if (!(d.y < 0)) {
      *sig = 8;
      return glm::dvec3(0.0);
    }
    *sig = 0;
    const glm::dvec3 p = o + (-o.y / d.y) * d;
    return glm::dvec3(kAlbedo / kPi * E(p, sig));
  }, 16);
}

// The same image scaled by k: a wrong closed form the test must reject.
std::function<glm::dvec3(int, int)> scaled(std::function<glm::dvec3(int, int)> f, double k) {
  return [f, k](int x, int y) { return k * f(x, y); };
}

// Light hits are hit-or-miss (Bernoulli-like): pooled, 1 % bias tolerance.
constexpr double kLightsBiasTolerance = 0.01;
using test::pooled;

class VulkanLights : public test::VulkanFixture {
 protected:
  // Accepts `exact` and rejects it scaled by 1.1.
  void expect_closed_form(const RenderResult& r, const std::function<glm::dvec3(int, int)>& exact, const char* what) {
    const ZTestReport ok = test::ztest_against_exact(r, exact, pooled(kLightsBiasTolerance));
    EXPECT_TRUE(ok.ok) << what << ": " << ok.summary();
    std::printf("%s: %s\n", what, ok.summary().c_str());
    const ZTestReport wrong = test::ztest_against_exact(r, scaled(exact, 1.1), pooled(kLightsBiasTolerance));
    EXPECT_FALSE(wrong.ok) << what << " ×1.1 should be rejected: " << wrong.summary();
  }
};

// The point and spot lights' colour: red at the intensity given, green and
// blue 0.8 and 0.6 of it; the suns' blue 0.9 of the rest.
const glm::dvec3 kPointTint(1.0, 0.8, 0.6), kSunTint(1.0, 1.0, 0.9);

Light point_light(glm::dvec3 position, double intensity) { return test::point_light(position, intensity * kPointTint); }

// E at p from a point light of intensity I (per channel: the red one; the
// others are 0.8 and 0.6 of it, which exact_image applies below).
double point_irradiance(glm::dvec3 p, glm::dvec3 light, double I) {
  const glm::dvec3 v = light - p;
  const double r2 = glm::dot(v, v);
  return I * v.y / std::sqrt(r2) / r2;
}

std::function<glm::dvec3(int, int)> tinted(std::function<glm::dvec3(int, int)> f, glm::dvec3 tint) {
  return [f, tint](int x, int y) { return tint * f(x, y); };
}

TEST_F(VulkanLights, PointLightOnAPlaneIsTheInverseSquareLaw) {
  Scene s = lit_plane_scene(256);
  const glm::dvec3 pos(0.3, 1.2, 0.4);
  s.lights.push_back(point_light(pos, 4.0));
  const RenderResult r = render(s);
  auto exact = plane_exact(s, [&](glm::dvec3 p, int*) { return point_irradiance(p, pos, 4.0); });
  expect_closed_form(r, tinted(exact, {1.0, 0.8, 0.6}), "point light");
}

TEST_F(VulkanLights, SpotLightIsAPointLightInsideItsConeAndDarkOutside) {
  Scene s = lit_plane_scene(256);
  const glm::dvec3 pos(0.0, 1.5, 0.5);
  const Light l = test::spot_light(pos, {0.2, -1.0, 0.1}, 6.0 * kPointTint, 35.0, 15.0);
  s.lights.push_back(l);
  const RenderResult r = render(s);
  const double cos_end = std::cos(35.0 * kPi / 180.0), cos_start = std::cos(20.0 * kPi / 180.0);
  auto exact = plane_exact(s, [&](glm::dvec3 p, int* sig) {
    const double c = glm::dot(glm::normalize(p - pos), l.direction);
    *sig = c >= cos_start ? 1 : c < cos_end ? 2 : 3;
    const double t = std::clamp((c - cos_end) / (cos_start - cos_end), 0.0, 1.0);
    return point_irradiance(p, pos, 6.0) * t * t * (3.0 - 2.0 * t);
  });
  expect_closed_form(r, tinted(exact, {1.0, 0.8, 0.6}), "spot light");
}

Light distant_light(glm::dvec3 toward, double E, double angle_deg) {
  return test::distant_light(toward, E * kSunTint, angle_deg);
}

TEST_F(VulkanLights, DeltaSunAndDiscSunGiveTheirIrradianceTimesCosine) {
  const glm::dvec3 toward(0.4, 1.0, -0.3);
  for (double angle : {0.0, 0.53, 20.0}) {
    Scene s = lit_plane_scene(128);
    s.lights.push_back(distant_light(toward, 2.0, angle));
    const RenderResult r = render(s);
    const double cos_theta = glm::normalize(toward).y;
    auto exact = plane_exact(s, [&](glm::dvec3, int*) { return 2.0 * cos_theta; });
    const std::string what = "distant light, angle " + std::to_string(angle) + " deg";
    expect_closed_form(r, tinted(exact, {1.0, 1.0, 0.9}), what.c_str());
  }
}

TEST_F(VulkanLights, SphereLightIrradianceIsPiLTimesRadiusOverDistanceSquared) {
  Scene s = lit_plane_scene(512);
  const glm::dvec3 c(0.4, 1.0, 1.0);
  const double radius = 0.35, L = 3.0;
  s.lights.push_back(test::sphere_light(c, radius, glm::dvec3(L)));
  const RenderResult r = render(s);
  auto exact = plane_exact(
      s,
      [&](glm::dvec3 p, int*) {
        const glm::dvec3 v = c - p;
        const double d2 = glm::dot(v, v);
        return kPi * L * radius * radius * (v.y / std::sqrt(d2)) / d2;
      },
      [&](glm::dvec3 o, glm::dvec3 d, glm::dvec3* seen) {
        const glm::dvec3 oc = o - c;
        const double b = glm::dot(oc, d), q = glm::dot(oc, oc) - radius * radius;
        if (b * b - q <= 0 || b > 0) return false;
        *seen = glm::dvec3(L);
        return true;
      });
  expect_closed_form(r, exact, "sphere light");
}

// The part of the segment o + t·d, t in [0, t_max], inside a sphere.
double segment_chord(glm::dvec3 c, double radius, glm::dvec3 o, glm::dvec3 d, double t_max) {
  const glm::dvec3 oc = o - c;
  const double b = glm::dot(oc, d), q = glm::dot(oc, oc) - radius * radius, disc = b * b - q;
  if (disc <= 0) return 0.0;
  const double t0 = std::max(0.0, -b - std::sqrt(disc)), t1 = std::min(t_max, -b + std::sqrt(disc));
  return std::max(0.0, t1 - t0);
}

// Light rays toward delta lights are ratio-tracked through the media: a
// point light and a delta sun seen through an absorbing sphere give
// ρ/π · E · e^(−σa·chord) on the plane (the camera ray's own chord too).
TEST_F(VulkanLights, DeltaLightRaysAreAttenuatedByTheMedia) {
  const glm::dvec3 c(0.2, 0.7, 0.6);
  const double radius = 0.45, sigma = 1.5;
  for (bool sun : {false, true}) {
    Scene s = lit_plane_scene(256);
    s.media.push_back(test::homogeneous_sphere("absorber", c, radius, glm::dvec3(sigma), glm::dvec3(0.0), 0.0,
                                               std::nullopt));
    const glm::dvec3 pos(0.3, 1.6, 0.5), toward = glm::normalize(glm::dvec3(-0.3, 1.0, 0.2));
    s.lights.push_back(sun ? distant_light(toward, 2.0, 0.0) : point_light(pos, 4.0));
    const RenderResult r = render(s);
    auto exact = test::exact_image(s.film.width, s.film.height, [&](double fx, double fy, int* sig) {
      const glm::dvec3 o = s.camera.position, d = test::film_ray(s.camera, s.film.width, s.film.height, fx, fy);
      *sig = 0;
      if (!(d.y < 0)) return glm::dvec3(0.0);
      const double t = -o.y / d.y;
      const glm::dvec3 p = o + t * d;
      const double seen = std::exp(-sigma * segment_chord(c, radius, o, d, t));
      if (sun) {
        const double chord = segment_chord(c, radius, p, toward, 1e9);
        *sig = chord > 0 ? 1 : 0;
        return glm::dvec3(1.0, 1.0, 0.9) * (seen * kAlbedo / kPi * 2.0 * toward.y * std::exp(-sigma * chord));
      }
      const glm::dvec3 v = pos - p;
      const double chord = segment_chord(c, radius, p, glm::normalize(v), glm::length(v));
      *sig = chord > 0 ? 1 : 0;
      return glm::dvec3(1.0, 0.8, 0.6) *
             (seen * kAlbedo / kPi * point_irradiance(p, pos, 4.0) * std::exp(-sigma * chord));
    }, 16);
    expect_closed_form(r, exact, sun ? "delta sun through an absorbing sphere" : "point light through an absorbing sphere");
  }
}

// Every kind of light at once, with a scattering fire over the plane and a
// sky: light selection over both groups (the sky and the disc sun; the fire,
// the point, spot and sphere lights), MIS of the fire, the sky, the disc and
// the sphere, delta light rays through the fire. GPU against the
// independently written CPU reference.
TEST_F(VulkanLights, EveryKindOfLightWithFireAndSkyMatchesCpu) {
  const auto dir = test::temp_dir("vk_lights_fire");
  // 256 spp: the pooled bias's SE is ~0.3 %, under a sixth of the 2 % tolerance.
  Scene s = test::fire_over_plane_scene(dir, test::Strategy::Mis, true, true, 24, 18, 256);
  s.lights.push_back(distant_light({-0.5, 1.0, -0.4}, 1.5, 5.0));
  s.lights.push_back(point_light({0.8, 0.6, -0.2}, 0.6));
  s.lights.push_back(test::spot_light({-0.6, 1.2, 0.3}, {0.3, -1.0, -0.2}, 2.0 * kPointTint, 40.0, 10.0));
  Light ball;
  ball.type = Light::Type::Sphere;
  ball.center = {0.6, 0.0, 0.5};
  ball.radius = 0.15;
  ball.temperature_k = 3000.0;
  ball.scale = 4.0;
  s.lights.push_back(ball);
  RenderResult gpu = render(s);
  test::expect_strategy_as_written(s, gpu);
  Scene c = s;
  CpuRenderer cpu(0);
  RenderResult ref = cpu.render(c, test::settings_for(c), {});
  EXPECT_EQ(cpu.majorant_violations(), 0u);
  test::expect_same_image(gpu, ref, 0.02, "GPU vs CPU, every kind of light with a fire and a sky");
}

}  // namespace
}  // namespace pyrolume
