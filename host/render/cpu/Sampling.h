#pragma once
// Sampling routines of the CPU reference, in double precision. The GLSL path uses
// the same names (sample_hg, hg_pdf, sample_free_flight) so they can be read side
// by side; this copy is deliberately plain.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/glm.hpp>

namespace pyrolume::cpu {

// Below this |g| the textbook HG inversion loses precision: (1 + g² − s²) cancels
// while 1/(2g) blows up. pbrt-v4 (SampleHenyeyGreenstein) samples isotropically
// there; the reference instead uses an algebraically equal form without the
// cancellation (see sample_hg_cos_theta), so it stays exactly HG for every g.
inline constexpr double kHgSmallG = 1e-3;

// Henyey–Greenstein phase function, in the *propagation* convention:
// cos_theta = dot(incoming travel direction, outgoing travel direction), so g > 0
// peaks at cos_theta = 1 (forward scattering, docs/scene-format.md "media").
//   p(cos θ) = (1 − g²) / (4π (1 + g² − 2 g cos θ)^{3/2})      [Henyey & Greenstein 1941]
// pbrt-v4 (eq. 11.12, HenyeyGreenstein()) writes "+ 2 g cos θ" because its cos θ is
// measured against wo = −(travel direction); the two are the same function.
inline double hg_pdf(double cos_theta, double g) {
  double denom = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * std::numbers::pi * denom * std::sqrt(denom));
}

// Inverse CDF of cos θ under HG (propagation convention), u in [0, 1):
//   cos θ = (1 + g² − s²) / (2 g),  s = (1 − g²) / (1 − g + 2 g u)
// (pbrt-v4 SampleHenyeyGreenstein, sec. 11.3.1, there with cos θ → −cos θ for wo).
// u = 0 gives cos θ = −1, u → 1 gives cos θ = 1. For |g| < kHgSmallG the same
// expression with ξ = 2u − 1, expanded and divided through by 2g:
//   cos θ = (ξ + g(3 + ξ²)/2 + g²ξ + g³(ξ² − 1)/2) / (1 + gξ)²
// which has no cancellation and tends to the isotropic ξ as g → 0.
inline double sample_hg_cos_theta(double g, double u) {
  double cos_theta;
  if (std::abs(g) < kHgSmallG) {
    double xi = 2.0 * u - 1.0, d = 1.0 + g * xi;
    cos_theta = (xi + 0.5 * g * (3.0 + xi * xi) + g * g * xi + 0.5 * g * g * g * (xi * xi - 1.0)) / (d * d);
  } else {
    double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    cos_theta = (1.0 + g * g - s * s) / (2.0 * g);
  }
  return std::clamp(cos_theta, -1.0, 1.0);
}

struct PhaseSample {
  glm::dvec3 direction;  // new travel direction, unit length
  double pdf = 0.0;      // solid-angle density, = hg_pdf(dot(dir, direction), g)
};

// Orthonormal basis around unit n (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited", JCGT 6(1)): branchless and stable for every n.
inline void orthonormal_basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
  double sign = std::copysign(1.0, n.z);
  double a = -1.0 / (sign + n.z);
  double bb = n.x * n.y * a;
  t = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * bb, -sign * n.x);
  b = glm::dvec3(bb, sign + n.y * n.y * a, -n.y);
}

// Scatter a photon travelling along unit `dir` by HG(g); u = two uniforms in [0,1).
inline PhaseSample sample_hg(const glm::dvec3& dir, double g, const glm::dvec2& u) {
  double cos_theta = sample_hg_cos_theta(g, u.x);
  double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  double phi = 2.0 * std::numbers::pi * u.y;
  glm::dvec3 t, b;
  orthonormal_basis(dir, t, b);
  glm::dvec3 w = sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * dir;
  return {glm::normalize(w), hg_pdf(cos_theta, g)};
}

struct BsdfSample {
  glm::dvec3 direction;  // new travel direction, unit length
  double pdf = 0.0;      // solid-angle density, = cos θ / π
};

// Cosine-weighted direction on the hemisphere around unit n (the Lambertian
// BSDF's importance sampling): p(ω) = cos θ / π, so f·cos θ/p = albedo exactly.
// Malley's method: a uniform point on the unit disk (r = √u₁, φ = 2π u₂)
// projected up onto the hemisphere (pbrt-v4 SampleCosineHemisphere, which uses
// the concentric map for the disk; the plain polar map is the same density).
inline BsdfSample sample_cosine_hemisphere(const glm::dvec3& n, const glm::dvec2& u) {
  double r = std::sqrt(u.x), phi = 2.0 * std::numbers::pi * u.y;
  double cos_theta = std::sqrt(std::max(0.0, 1.0 - u.x));
  glm::dvec3 t, b;
  orthonormal_basis(n, t, b);
  glm::dvec3 w = r * std::cos(phi) * t + r * std::sin(phi) * b + cos_theta * n;
  return {glm::normalize(w), cos_theta / std::numbers::pi};
}

// Free-flight distance in a homogeneous medium, sampled from
// p(t) = σt exp(−σt t) by inversion: t = −ln(1 − u)/σt (pbrt-v4 SampleExponential).
// σt <= 0: the photon never collides (infinity).
inline double sample_free_flight(double sigma_t, double u) {
  if (!(sigma_t > 0.0)) return std::numeric_limits<double>::infinity();
  return -std::log1p(-u) / sigma_t;
}

}  // namespace pyrolume::cpu
