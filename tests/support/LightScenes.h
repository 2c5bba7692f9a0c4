#pragma once
// Light builders shared by the lights tests (header-only): the scene's
// analytic lights, the emission parameters of a temperature grid, and a
// lat-long sky with the structure an environment sampler must get right.
#include <functional>

#include <glm/glm.hpp>

#include "image/Image.h"
#include "light/EmissionCdf.h"
#include "scene/Scene.h"

namespace pyrolume::test {

// ----------------------------------------------------------------- lights ----

// intensity: radiant intensity (W/sr).
inline Light point_light(glm::dvec3 position, glm::dvec3 intensity) {
  Light l;
  l.type = Light::Type::Point;
  l.position = position;
  l.rgb = intensity;
  return l;
}

// A point light shining along `direction` (normalized here) inside a cone of
// half-angle cone_deg, with a soft edge falloff_deg wide.
inline Light spot_light(glm::dvec3 position, glm::dvec3 direction, glm::dvec3 intensity, double cone_deg,
                        double falloff_deg) {
  Light l = point_light(position, intensity);
  l.type = Light::Type::Spot;
  l.direction = glm::normalize(direction);
  l.cone_deg = cone_deg;
  l.falloff_deg = falloff_deg;
  return l;
}

// A sun toward `direction` (normalized here) of the given irradiance; angle 0:
// a delta light, else a disc of that angular diameter.
inline Light distant_light(glm::dvec3 direction, glm::dvec3 irradiance, double angle_deg) {
  Light l;
  l.type = Light::Type::Distant;
  l.direction = glm::normalize(direction);
  l.rgb = irradiance;
  l.angle_deg = angle_deg;
  return l;
}

inline Light sphere_light(glm::dvec3 center, double radius, glm::dvec3 radiance) {
  Light l;
  l.type = Light::Type::Sphere;
  l.center = center;
  l.radius = radius;
  l.rgb = radiance;
  return l;
}

// --------------------------------------------------------------- emission ----

// An emissive grid's parameters for EmissionCdf::build: blackbody emission
// from the temperature grid (T = 1000 K per unit of its value, none at or
// below cutoff_k) times `scale`.
inline EmissionParams temperature_emission(glm::dvec3 sigma_a, double cutoff_k, double scale) {
  EmissionParams p;
  p.sigma_a = sigma_a;
  p.emits_temperature = true;
  p.temperature.scale = 1000.0;
  p.temperature.cutoff_k = cutoff_k;
  p.emission.scale = scale;
  p.emission.is_grid = true;
  return p;
}

// -------------------------------------------------------------------- sky ----

// A small bright sun on a sky map: `add` over the disc |(u, v) − uv|² < radius2.
struct SkySun {
  glm::dvec2 uv;
  double radius2;
  glm::dvec3 add;
};

// A W × H lat-long map: gradient(u, v) at texel centres ((u, v) in (0, 1),
// v = 0 the top row), black where black(i, j), then the sun added.
inline Image sky_image(int W, int H, const std::function<glm::dvec3(double u, double v)>& gradient,
                       const std::function<bool(int i, int j)>& black, const SkySun& sun) {
  Image img = make_image(W, H);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const double v = (j + 0.5) / H, u = (i + 0.5) / W;
      glm::dvec3 c = gradient(u, v);
      if (black(i, j)) c = glm::dvec3(0.0);
      const double du = u - sun.uv.x, dv = v - sun.uv.y;
      if (du * du + dv * dv < sun.radius2) c += sun.add;
      for (int k = 0; k < 3; ++k) img.at(i, j, k) = float(c[k]);
    }
  return img;
}

}  // namespace pyrolume::test
