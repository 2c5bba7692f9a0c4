// CPU reference with surfaces (issue 6, BSDF/phase sampling only): the cases
// both backends share run from tests/support/SurfaceSuite.h (Surface.*/"cpu");
// here, the CPU-only ones: the cosine-hemisphere sampler, a surface clipping
// the medium behind it against a closed form, a surface lit by an emissive
// medium (both estimators agree) and determinism across thread counts.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/cpu/CpuRenderer.h"
#include "render/cpu/Rng.h"
#include "render/cpu/Sampling.h"
#include "support/Stats.h"
#include "support/SurfaceSuite.h"
#include "util/Math.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Surface, "cpu");
}  // namespace test

namespace {

using test::pixel_mean;
using test::plane_shape;
using test::pooled;
using test::ZTestReport;


RenderResult render_surface(const Scene& s, int threads = 0) {
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

// ----------------------------------------------------------- occlusion ----

// A black infinite plane through the centre of an absorbing emissive sphere:
// only the half in front of the plane is seen, so with the chord ℓ clipped at
// the plane, L = Le (1 − e^{−σa ℓ}) exactly (per channel, a closed form the
// pixel quadrature integrates). The full chord must fail: media behind the
// surface do not count.
TEST(CpuSurface, SurfaceClipsMediumBehindIt) {
  const glm::dvec3 sigma_a(0.6, 1.2, 2.4), Le(1.0, 0.7, 0.4);
  const glm::dvec3 c0(0.2, 0.1, 0.0);
  const double R = 1.2;
  for (const EmissionEstimator estimator : {EmissionEstimator::Absorption, EmissionEstimator::Collision}) {
    Scene s = test::analytic_base_scene(24, 24, 512);
    s.integrator.emission_estimator = estimator;
    s.background = glm::dvec3(3.0);  // hidden everywhere by the plane
    s.media.push_back(test::homogeneous_sphere("half", c0, R, sigma_a, glm::dvec3(0.0), 0.0, Le));
    s.shapes.push_back(plane_shape({0, 0, 0}, {0, 0, -1}, {0, 0}, glm::dvec3(0.0)));
    RenderResult r = render_surface(s);
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
    EXPECT_TRUE(ok.ok) << to_string(estimator) << ": " << ok.summary();
    std::printf("%s clipped: %s\n", to_string(estimator), ok.summary().c_str());
    ZTestReport full = test::ztest_against_exact(r, exact_for(false), pooled());
    EXPECT_FALSE(full.ok) << to_string(estimator) << ": " << full.summary();
  }
}

// ---------------------------------------------------- lit by the medium ----

// A homogeneous emissive, scattering sphere above a white diffuse plane, black
// sky: the plane is lit only through BSDF-sampled paths that find the sphere.
// Plane pixels must be > 0 and finite, and both emission estimators must
// converge to the same image.
Scene lit_plane_scene(EmissionEstimator estimator, uint32_t seed) {
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
  Scene s = lit_plane_scene(EmissionEstimator::Collision, 3);
  RenderResult r = render_surface(s);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  for (double v : r.sum) ASSERT_TRUE(std::isfinite(v));
  // Bottom rows: the plane in front of the sphere (no medium on the camera ray).
  double near_sum = 0.0;
  for (int x = 0; x < r.width; ++x) near_sum += pixel_mean(r, x, r.height - 1).x;
  EXPECT_GT(near_sum / r.width, 0.0);

  ZTestReport same = test::ztest_images(render_surface(lit_plane_scene(EmissionEstimator::Absorption, 4)), r, pooled(0.03));
  EXPECT_TRUE(same.ok) << same.summary();
  std::printf("absorption vs collision: %s\n", same.summary().c_str());
}

TEST(CpuSurface, DeterministicAcrossThreadCounts) {
  Scene s = lit_plane_scene(EmissionEstimator::Absorption, 9);
  s.film.spp = 8;
  RenderResult a = render_surface(s, 1), b = render_surface(s, 3);
  EXPECT_EQ(a.sum, b.sum);
  EXPECT_EQ(a.sum_sq, b.sum_sq);
  EXPECT_EQ(a.events, b.events);
}

}  // namespace
}  // namespace pyrolume
