#pragma once
// Scenes with known answers for the renderer tests (header-only). Builders return
// plain Scene objects (the same as parsed JSON would give); the closed forms are
// computed here, independently of any renderer: own camera model (docs/scene-format.md "camera"
// convention), own ray/bounds code, own pixel-area quadrature.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "render/Render.h"
#include "scene/Scene.h"

namespace pyrolume::test {

// ---------------------------------------------------------------- builders ----

// The render settings a scene's film asks for (what the CLI does without overrides).
inline RenderSettings settings_for(const Scene& s) {
  RenderSettings rs;
  rs.width = s.film.width;
  rs.height = s.film.height;
  rs.spp = s.film.spp;
  rs.seed = s.film.seed;
  rs.aovs = s.film.aovs;
  return rs;
}

inline Scene analytic_base_scene(int width, int height, int spp) {
  Scene s;
  s.file = "<analytic>";
  s.camera.position = {0, 0, -5};
  s.camera.look_at = {0, 0, 0};
  s.camera.up = {0, 1, 0};
  s.camera.fov_deg = 40.0;
  s.film.width = width;
  s.film.height = height;
  s.film.spp = spp;
  s.film.seed = 7;
  s.integrator.max_depth = 8;
  s.background = glm::dvec3(0.0);
  return s;
}

inline Medium homogeneous_sphere(const std::string& name, glm::dvec3 center, double radius, glm::dvec3 sigma_a,
                                 glm::dvec3 sigma_s, double g, std::optional<glm::dvec3> Le_rgb,
                                 double scale = 1.0) {
  Medium m;
  m.name = name;
  m.type = Medium::Type::Homogeneous;
  m.bounds.kind = Bounds::Kind::Sphere;
  m.bounds.center = center;
  m.bounds.radius = radius;
  m.sigma_a = sigma_a;
  m.sigma_s = sigma_s;
  m.g = g;
  m.emission.rgb = Le_rgb;
  m.emission.scale = scale;
  return m;
}

inline Medium homogeneous_box(const std::string& name, glm::dvec3 lo, glm::dvec3 hi, glm::dvec3 sigma_a,
                              glm::dvec3 sigma_s, double g, std::optional<glm::dvec3> Le_rgb, double scale = 1.0) {
  Medium m = homogeneous_sphere(name, {0, 0, 0}, 1.0, sigma_a, sigma_s, g, Le_rgb, scale);
  m.bounds.kind = Bounds::Kind::Box;
  m.bounds.min = lo;
  m.bounds.max = hi;
  return m;
}

// analytic_base_scene with one medium over `background`.
inline Scene one_medium_scene(int width, int height, int spp, glm::dvec3 background, Medium medium) {
  Scene s = analytic_base_scene(width, height, spp);
  s.background = background;
  s.media.push_back(std::move(medium));
  return s;
}

// (a) An absorbing emissive sphere (σs = 0), chromatic σa, nonzero background,
// placed off-centre (right along cross(forward, up) and up) so that a flipped
// image axis fails the test. Exact: single_collision_exact().
inline Scene absorbing_sphere_scene(int width = 40, int height = 32, int spp = 1024) {
  // Camera looks along +z with up +y: image right = cross(+z, +y) = −x.
  return one_medium_scene(width, height, spp, {0.05, 0.1, 0.2},
                          homogeneous_sphere("ball", {-0.5, 0.35, 0.0}, 1.0, {0.4, 1.0, 2.5}, {0, 0, 0}, 0.0,
                                             glm::dvec3(1.0, 0.55, 0.25), 1.5));
}

// (d) The box version of (a): seen obliquely, so three faces and slanted
// silhouette edges are in view.
inline Scene absorbing_box_scene(int width = 40, int height = 32, int spp = 1024) {
  Scene s = one_medium_scene(width, height, spp, {0.15, 0.05, 0.02},
                             homogeneous_box("block", {-0.8, -0.6, -0.7}, {0.9, 0.7, 0.6}, {0.3, 0.9, 2.0}, {0, 0, 0},
                                             0.0, glm::dvec3(0.4, 1.0, 1.6), 1.2));
  s.camera.position = {2.5, 1.8, -4.5};
  s.camera.look_at = {0.1, 0.1, 0.0};
  return s;
}

// Thin, hot media (issue 23): σa·d ≪ 1 with Le large, so L ≈ Le·σa·d comes
// from emission the collision estimator would rarely meet. The integrator is
// left at "auto", which must pick the line estimator (docs/rendering.md).
// (e) A sphere, σa·2r = 0.004 … 0.016, chromatic.
inline Scene thin_sphere_scene(int width = 40, int height = 32, int spp = 256) {
  return one_medium_scene(width, height, spp, {0.05, 0.1, 0.2},
                          homogeneous_sphere("flame", {-0.4, 0.3, 0.0}, 1.0, {0.002, 0.004, 0.008}, {0, 0, 0}, 0.0,
                                             glm::dvec3(1.0, 0.6, 0.3), 200.0));
}

// (f) A slab 0.1 thick across the view, seen a little obliquely (σa·d = 0.002 …
// 0.005 along the normal); or, with optical_depth, the same slab at σa·d =
// optical_depth per channel and Le = 1/optical_depth (L ≈ 1).
inline Scene thin_slab_scene(int width = 40, int height = 32, int spp = 256, double optical_depth = 0.0) {
  const double d = 0.1;
  const glm::dvec3 sigma_a = optical_depth > 0.0 ? glm::dvec3(optical_depth / d) : glm::dvec3(0.02, 0.03, 0.05);
  const double scale = optical_depth > 0.0 ? 1.0 / optical_depth : 500.0;
  Scene s = one_medium_scene(width, height, spp, {0.15, 0.05, 0.02},
                             homogeneous_box("slab", {-1.5, -1.0, -0.5 * d}, {1.2, 1.1, 0.5 * d}, sigma_a, {0, 0, 0},
                                             0.0, glm::dvec3(1.0, 0.8, 0.6), scale));
  s.camera.position = {0.6, 0.4, -5.0};
  s.camera.look_at = {0.0, 0.0, 0.0};
  return s;
}

// A scattering, absorbing, emissive sphere rendered with max_depth = 0: every
// path that would scatter ends with 0, so scattering acts as pure extinction and
// single_collision_exact() holds with σt = σa + σs.
inline Scene depth0_sphere_scene(int width = 32, int height = 32, int spp = 1024) {
  Scene s = one_medium_scene(width, height, spp, {0.2, 0.1, 0.05},
                             homogeneous_sphere("ball", {0.3, -0.2, 0.0}, 1.2, {0.5, 0.3, 0.2}, {0.6, 1.2, 2.0}, 0.7,
                                                glm::dvec3(0.8, 1.0, 1.3), 1.0));
  s.integrator.max_depth = 0;
  return s;
}

// (b) Camera inside a large emissive, scattering, absorbing sphere: equilibrium,
// L = Le in every pixel and channel (background 0).
// Why R = 20 is "infinite" here: every collision absorbs with probability σa/σt,
// so along the path's total length absorptions form a Poisson process of rate
// σa (thinning of the collision process of rate σt). A path must travel at least
// the distance to the boundary, d = R − |camera − centre| ≈ 18.9, to escape, so
// P(escape) <= exp(−σa_min·d) = exp(−18.9) ≈ 6e-9. Truncation by max_depth = 64
// needs 65 scatterings before absorption: P = (σs/σt)^65 <= 0.75^65 ≈ 8e-9. Both
// are far below the 1e-6 relative tolerance the SE = 0 pixels are held to.
inline Scene equilibrium_sphere_scene(int width = 32, int height = 32, int spp = 64) {
  Scene s = one_medium_scene(width, height, spp, {0, 0, 0},
                             homogeneous_sphere("furnace", {0, 0, 0}, 20.0, {1.0, 1.5, 2.0}, {3.0, 2.0, 1.0}, 0.5,
                                                glm::dvec3(0.9, 0.6, 0.3), 2.0));
  s.camera.position = {1.0, 0.5, -0.5};
  s.camera.look_at = {1.0, 0.5, 1.0};
  s.integrator.max_depth = 64;
  return s;
}

// Expected radiance of equilibrium_sphere_scene: Le of its one medium.
inline glm::dvec3 equilibrium_radiance(const Scene& s) {
  const Medium& m = s.media.at(0);
  return m.emission.scale * m.emission.rgb.value();
}

// White furnace: a non-absorbing, non-emissive scattering sphere under a constant
// background. Every path escapes eventually with the background's value, so
// L = background exactly (energy conservation of the walk and of HG sampling).
// Optical radius σs·R <= 2: P(more than 1000 scatterings) is astronomically small.
inline Scene white_furnace_scene(int width = 24, int height = 24, int spp = 64) {
  Scene s = one_medium_scene(width, height, spp, {0.3, 0.6, 0.9},
                             homogeneous_sphere("cloud", {0, 0, 0}, 1.0, {0, 0, 0}, {0.5, 1.0, 2.0}, -0.3, std::nullopt));
  s.integrator.max_depth = 1000;
  return s;
}

// (c) Chromatic scattering with two overlapping media (sphere + box, different
// HG g of opposite sign, chromatic σa and σs, both emissive), nonzero background.
// No closed form: for GPU-vs-CPU comparison (ztest_images).
inline Scene chromatic_scattering_scene(int width = 32, int height = 32, int spp = 256) {
  Scene s = analytic_base_scene(width, height, spp);
  s.camera.position = {0.4, 0.6, -4.2};
  s.camera.look_at = {0.2, 0.0, 0.0};
  s.integrator.max_depth = 8;
  s.background = {0.1, 0.12, 0.2};
  s.media.push_back(homogeneous_sphere("ball", {-0.3, 0.0, 0.0}, 1.0, {0.6, 0.3, 0.15}, {0.8, 1.4, 2.0}, 0.6,
                                       glm::dvec3(2.0, 0.8, 0.3), 1.0));
  s.media.push_back(homogeneous_box("slab", {-0.2, -0.9, -0.9}, {1.3, 0.6, 0.8}, {0.2, 0.25, 0.3}, {1.0, 0.6, 0.3},
                                    -0.4, glm::dvec3(0.2, 0.5, 1.0), 0.5));
  return s;
}

// --------------------------------------------------------- closed forms ----

// Camera ray through continuous film point (fx, fy) in pixels (0,0 = top-left),
// docs/scene-format.md "camera": vertical fov, image x along normalize(cross(forward, up)).
inline glm::dvec3 film_ray(const Camera& cam, int width, int height, double fx, double fy) {
  const glm::dvec3 f = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 r = glm::normalize(glm::cross(f, cam.up));
  const glm::dvec3 u = glm::cross(r, f);
  const double h = std::tan(cam.fov_deg * std::numbers::pi / 360.0);
  const double w = h * double(width) / double(height);
  return glm::normalize(f + (fx / width * 2.0 - 1.0) * w * r + (1.0 - fy / height * 2.0) * h * u);
}

// Length of the ray's part (t >= 0) inside the bounds, plus a signature that
// changes wherever the length is not smooth (silhouette; box entry/exit face),
// used to refine the pixel quadrature there.
struct Chord {
  double length = 0.0;
  int signature = 0;
};

inline Chord chord(const Bounds& b, const glm::dvec3& o, const glm::dvec3& d) {
  if (b.kind == Bounds::Kind::Sphere) {
    // |o + t d − c|² = r²  →  t² + 2 (oc·d) t + |oc|² − r² = 0 (|d| = 1).
    glm::dvec3 oc = o - b.center;
    double bh = glm::dot(oc, d), c = glm::dot(oc, oc) - b.radius * b.radius;
    double disc = bh * bh - c;
    if (disc <= 0.0) return {};
    double sq = std::sqrt(disc);
    double t0 = std::max(0.0, -bh - sq), t1 = -bh + sq;
    if (t1 <= t0) return {};
    return {t1 - t0, 1};
  }
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  int in_face = -1, out_face = -1;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < b.min[a] || o[a] > b.max[a]) return {};
      continue;
    }
    double ta = (b.min[a] - o[a]) / d[a], tb = (b.max[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) t0 = ta, in_face = a;
    if (tb < t1) t1 = tb, out_face = a;
  }
  if (t1 <= t0) return {};
  return {t1 - t0, 1 + (in_face + 1) * 4 + (out_face + 1) * 16};
}

// Radiance along one ray for a scene with one homogeneous medium when no path
// scatters (σs = 0, or max_depth = 0 so that scattering only removes paths):
// with τ = σt·ℓ along the chord ℓ, the first collision absorbs with probability
// σa/σt, so
//   L = (σa/σt)·Le·(1 − e^{−τ}) + background·e^{−τ}     (per channel)
// which for σs = 0 is the familiar Le·(1 − e^{−σa ℓ}) + bg·e^{−σa ℓ}.
inline glm::dvec3 single_collision_radiance(const Scene& s, const glm::dvec3& o, const glm::dvec3& d, int* sig = nullptr) {
  if (s.media.size() != 1) throw std::invalid_argument("single_collision_radiance: needs exactly one medium");
  const Medium& m = s.media[0];
  glm::dvec3 Le = m.emission.emits() && m.emission.rgb ? m.emission.scale * *m.emission.rgb : glm::dvec3(0.0);
  Chord ch = chord(m.bounds, o, d);
  if (sig) *sig = ch.signature;
  glm::dvec3 L;
  for (int c = 0; c < 3; ++c) {
    double st = m.sigma_a[c] + m.sigma_s[c];
    double T = std::exp(-st * ch.length);
    double absorbed = st > 0.0 ? m.sigma_a[c] / st * Le[c] * (1.0 - T) : 0.0;
    L[c] = absorbed + s.background[c] * T;
  }
  return L;
}

// Average of the radiance over a pixel's area (what a box-filtered, jittered
// renderer converges to). base×base midpoint cells; a cell is split in 4 (down to
// max_level times) when its 4 corners and centre disagree in chord signature (it
// straddles a silhouette or a box edge, where L jumps or kinks) or when L varies
// across it by more than steep_rel of its size (the sqrt(distance) rise of the
// chord just inside a sphere's silhouette, where the midpoint rule's O(h²·L'')
// error is largest). Measured on the shipped scenes at 1024 spp against base 64 /
// level 10: the defaults err by <= 0.03 of a pixel's standard error (~0.2 s per
// 40×32 image); cpu_analytic_test checks a finer quadrature agrees.
inline glm::dvec3 pixel_average(const std::function<glm::dvec3(double fx, double fy, int* sig)>& L, int x, int y,
                                int base = 8, int max_level = 6, double steep_rel = 0.05) {
  std::function<glm::dvec3(double, double, double, int)> cell = [&](double x0, double y0, double h,
                                                                      int level) -> glm::dvec3 {
    int sc, s0, s1, s2, s3;
    glm::dvec3 mid = L(x0 + 0.5 * h, y0 + 0.5 * h, &sc);
    if (level < max_level) {
      glm::dvec3 v[4] = {L(x0, y0, &s0), L(x0 + h, y0, &s1), L(x0, y0 + h, &s2), L(x0 + h, y0 + h, &s3)};
      double lo = std::min({mid.x, mid.y, mid.z}), hi = std::max({mid.x, mid.y, mid.z});
      double spread = 0.0;
      for (const glm::dvec3& c : v)
        for (int k = 0; k < 3; ++k) {
          spread = std::max(spread, std::abs(c[k] - mid[k]));
          lo = std::min(lo, c[k]);
          hi = std::max(hi, c[k]);
        }
      bool steep = spread > steep_rel * std::max(std::abs(lo), std::abs(hi));
      if (s0 != sc || s1 != sc || s2 != sc || s3 != sc || steep) {
        double hh = 0.5 * h;
        return 0.25 * (cell(x0, y0, hh, level + 1) + cell(x0 + hh, y0, hh, level + 1) +
                       cell(x0, y0 + hh, hh, level + 1) + cell(x0 + hh, y0 + hh, hh, level + 1));
      }
    }
    return mid;
  };
  glm::dvec3 acc(0.0);
  double h = 1.0 / base;
  for (int j = 0; j < base; ++j)
    for (int i = 0; i < base; ++i) acc += cell(x + i * h, y + j * h, h, 0);
  return acc / double(base * base);
}

// Exact expected pixel means of a single-medium, non-scattering (or max_depth 0)
// scene, precomputed for the scene's film size; returns a lookup for
// ztest_against_exact.
// pixel_average of L over every pixel of a W×H film, precomputed; returns a
// lookup for ztest_against_exact.
inline std::function<glm::dvec3(int, int)> pixel_average_image(
    int W, int H, const std::function<glm::dvec3(double fx, double fy, int* sig)>& L, int base = 8,
    int max_level = 6, double steep_rel = 0.05) {
  auto img = std::make_shared<std::vector<glm::dvec3>>(size_t(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) (*img)[size_t(y) * W + x] = pixel_average(L, x, y, base, max_level, steep_rel);
  return [img, W](int x, int y) { return (*img)[size_t(y) * W + x]; };
}

inline std::function<glm::dvec3(int, int)> single_collision_exact(const Scene& s, int base = 8, int max_level = 6, double steep_rel = 0.05) {
  const int W = s.film.width, H = s.film.height;
  auto L = [&](double fx, double fy, int* sig) {
    return single_collision_radiance(s, s.camera.position, film_ray(s.camera, W, H, fx, fy), sig);
  };
  return pixel_average_image(W, H, L, base, max_level, steep_rel);
}

}  // namespace pyrolume::test
