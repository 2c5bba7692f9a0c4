#include "render/cpu/Lights.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/cpu/Intersect.h"
#include "render/cpu/Sampling.h"

namespace pyrolume::cpu {

std::vector<AnalyticLight> analytic_lights(const std::vector<Light>& scene_lights) {
  std::vector<AnalyticLight> out;
  for (const Light& l : scene_lights) {
    AnalyticLight a;
    a.light = l;
    a.light.direction = glm::normalize(l.direction);
    a.value = light_value(l);
    if (l.type == Light::Type::Distant) {
      a.disc_omc = disc_one_minus_cos(l);
      a.disc_L = disc_radiance(l);
    }
    if (l.type == Light::Type::Spot) a.cone = spot_cone(l);
    out.push_back(a);
  }
  return out;
}

bool in_cone(const glm::dvec3& w, const glm::dvec3& axis, double omc) {
  const glm::dvec3 e = w - axis;
  return glm::dot(e, e) <= 2.0 * omc;
}

namespace {

// A direction uniform in that cone, solid-angle pdf 1/(2π omc):
// 1 − cos α = u₁ omc (docs/lights.md "Sampling").
glm::dvec3 sample_cone(const glm::dvec3& axis, double omc, double u1, double u2) {
  const double x = u1 * omc;  // 1 − cos α
  const double cos_a = 1.0 - x, sin_a = std::sqrt(std::max(0.0, x * (2.0 - x)));
  const double phi = 2.0 * std::numbers::pi * u2;
  glm::dvec3 t, b;
  orthonormal_basis(axis, t, b);
  return glm::normalize(sin_a * std::cos(phi) * t + sin_a * std::sin(phi) * b + cos_a * axis);
}

// The cone a sphere light subtends from o: its axis and 1 − cos θ_max =
// (r²/d²)/(1 + √(1 − r²/d²)) (docs/lights.md "Sampling"); 0 from inside.
double sphere_cone(const AnalyticLight& l, const glm::dvec3& o, glm::dvec3& axis) {
  const glm::dvec3 v = l.light.center - o;
  const double d2 = glm::dot(v, v), s2 = l.light.radius * l.light.radius / d2;
  if (!(s2 < 1.0)) return 0.0;
  axis = v / std::sqrt(d2);
  return s2 / (1.0 + std::sqrt(1.0 - s2));
}

}  // namespace

SphereLightHit intersect_sphere_lights(const WalkLights& lights, const glm::dvec3& o, const glm::dvec3& d,
                                       double t_max) {
  SphereLightHit best;
  for (size_t j = 0; j < lights.analytic.size(); ++j) {
    const AnalyticLight& l = lights.analytic[j];
    if (!l.is_sphere()) continue;
    const RayInterval r = intersect_sphere(o, d, l.light.center, l.light.radius);
    if (!r.hit) continue;
    const bool outside = r.t0 > 0.0;
    const double t = outside ? r.t0 : r.t1;
    if (!(t > 0.0 && t < t_max)) continue;
    best = {int(j), t, outside};
    t_max = t;
  }
  return best;
}

double unidirectional_weight(const WalkLights& lights, const RayMis& mis) {
  if (!lights.active() || !(mis.pdf_dir > 0.0) || !(mis.p_light > 0.0)) return 1.0;
  if (lights.selection.strategy == LightStrategy::LightOnly) return 0.0;
  return power_heuristic(mis.pdf_dir, mis.p_light);
}

double light_direction_pdf(const WalkLights& lights, const glm::dvec3& o, const glm::dvec3& d) {
  double p = 0.0;
  if (lights.selection.p_env > 0.0) p += lights.selection.p_env * lights.environment->pdf(d);
  for (size_t j = 0; j < lights.cdf.size(); ++j)
    if (lights.selection.p_medium[j] > 0.0) p += lights.selection.p_medium[j] * lights.cdf[j]->direction_pdf(o, d);
  for (size_t j = 0; j < lights.analytic.size(); ++j) {
    const double P = lights.selection.p_light[j];
    const AnalyticLight& l = lights.analytic[j];
    if (!(P > 0.0)) continue;
    glm::dvec3 axis = l.light.direction;
    const double omc = l.is_disc() ? l.disc_omc : l.is_sphere() ? sphere_cone(l, o, axis) : 0.0;
    if (omc > 0.0 && in_cone(d, axis, omc)) p += P / (2.0 * std::numbers::pi * omc);
  }
  return p;
}

bool light_direction(const WalkLights& lights, const glm::dvec3& o, Pcg32& rng, LightPick& pick) {
  double u = rng.uniform();
  const double u_env = rng.uniform(), v_env = rng.uniform();
  const glm::dvec3 u3(rng.uniform(), rng.uniform(), rng.uniform());
  pick = LightPick{};
  if (u < lights.selection.p_env) {
    const EnvSample es = lights.environment->sample({u_env, v_env});
    pick.dir = es.dir;
    return es.pdf > 0.0;
  }
  u -= lights.selection.p_env;
  // The media, then the analytic lights; rounding past the last one picks it.
  const size_t n_media = lights.cdf.size();
  int j = -1;
  for (size_t i = 0; i < n_media + lights.analytic.size(); ++i) {
    const double p = i < n_media ? lights.selection.p_medium[i] : lights.selection.p_light[i - n_media];
    if (!(p > 0.0)) continue;
    j = int(i);
    if (u < p) break;
    u -= p;
  }
  if (j < 0) return false;
  if (size_t(j) < n_media) {
    const EmissionSample es = lights.cdf[j]->sample_from(o, u_env, v_env, u3);
    if (!(es.pdf > 0.0)) return false;
    const glm::dvec3 v = es.p - o;
    const double r = glm::length(v);
    if (!(r > 0.0)) return false;
    pick.dir = v / r;
    return true;
  }
  const int k = j - int(n_media);
  const AnalyticLight& l = lights.analytic[k];
  switch (l.light.type) {
    case Light::Type::Distant:
      if (l.is_disc()) {
        pick.dir = sample_cone(l.light.direction, l.disc_omc, u_env, v_env);
      } else {
        pick.dir = l.light.direction;
        pick.delta = k;
        pick.Li = l.value;
      }
      return true;
    case Light::Type::Sphere: {
      glm::dvec3 axis;
      const double omc = sphere_cone(l, o, axis);
      if (!(omc > 0.0)) return false;  // o inside the sphere: no sample
      pick.dir = sample_cone(axis, omc, u_env, v_env);
      return true;
    }
    case Light::Type::Point:
    case Light::Type::Spot: {
      const glm::dvec3 v = l.light.position - o;
      const double r2 = glm::dot(v, v);
      if (!(r2 > 0.0)) return false;
      const double r = std::sqrt(r2);
      pick.dir = v / r;
      pick.delta = k;
      pick.t_max = r;
      // The spot's falloff by the angle between its axis and the direction from it to o.
      const double falloff =
          l.light.type == Light::Type::Spot ? spot_falloff(l.cone, -glm::dot(l.light.direction, pick.dir)) : 1.0;
      pick.Li = l.value * (falloff / r2);
      return true;
    }
  }
  return false;
}

}  // namespace pyrolume::cpu
