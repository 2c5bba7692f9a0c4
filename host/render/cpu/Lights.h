#pragma once
// The CPU reference's lights as its walks read them (docs/lights.md,
// docs/mis.md): what next-event estimation samples (the environment, the
// emissive grids' emission CDFs, the analytic lights), the direction pdfs of
// that mixture, and the sphere lights that rays meet on their way. Written
// apart from the GPU's shaders/lights.glsl.
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "light/AnalyticLights.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/cpu/Rng.h"
#include "scene/Scene.h"

namespace pyrolume::cpu {

// A light of the scene's `lights` array as the walks read it (docs/lights.md
// "Analytic lights"), its values computed once.
struct AnalyticLight {
  Light light;                  // type, direction (unit), position, center, radius
  glm::dvec3 value{0.0};        // light_value: E (distant), I (point, spot) or L (sphere)
  glm::dvec3 disc_L{0.0};       // a disc sun's radiance
  double disc_omc = 0.0;        // a disc sun's 1 − cos θ (0: a delta light)
  SpotCone cone;                // a spot's soft edge
  bool is_disc() const { return light.type == Light::Type::Distant && disc_omc > 0.0; }
  bool is_sphere() const { return light.type == Light::Type::Sphere; }
};

// The scene's `lights`, each with its values computed once.
std::vector<AnalyticLight> analytic_lights(const std::vector<Light>& lights);

// What next-event estimation samples (host/light/LightSelection.h), and the
// analytic lights, which rays also meet (discs on escape, spheres on the way)
// whether they are sampled or not; the environment map, when there is one.
struct WalkLights {
  LightSelection selection;
  std::vector<const EmissionCdf*> cdf;  // per scene medium; null: not a light
  std::vector<AnalyticLight> analytic;  // per entry of Scene::lights (selection.p_light)
  const EnvironmentMap* environment = nullptr;
  bool active() const { return selection.strategy != LightStrategy::Bsdf; }
};

// Whether unit w lies in the cone of 1 − cos θ = omc around unit axis:
// |w − axis|² = 2(1 − cos α), which keeps the sun's 1e-5 (no 1 − cos).
bool in_cone(const glm::dvec3& w, const glm::dvec3& axis, double omc);

// The closest sphere light along a ray with 0 < t < t_max. From inside a
// sphere the ray ends at its far side with nothing: it emits outward only.
struct SphereLightHit {
  int light = -1;  // index into WalkLights::analytic; −1: none
  double t = 0.0;
  bool outside = false;
};
SphereLightHit intersect_sphere_lights(const WalkLights& lights, const glm::dvec3& o, const glm::dvec3& d,
                                       double t_max);

// The MIS state of the ray being tracked (docs/mis.md): the solid-angle pdf
// with which its direction was sampled at its vertex (0 for the camera ray and
// for light rays, whose radiance is never weighted), and the solid-angle pdf
// with which next-event estimation at that vertex picks the same direction,
// times its number of samples there.
struct RayMis {
  double pdf_dir = 0.0;
  double p_light = 0.0;
};

// MIS weight of the radiance that BSDF/phase sampling finds along its ray
// before the next real event (emission at tentative collisions, the
// environment on escape): the same for all of it, since both strategies
// estimate that radiance along the same direction. 1 where next-event
// estimation cannot pick the direction or there is none.
double unidirectional_weight(const WalkLights& lights, const RayMis& mis);

// The solid-angle pdf with which next-event estimation at o picks direction
// d: the environment map's, for each emissive grid the pdf of the direction
// toward a point drawn from its emission CDF (EmissionCdf::direction_pdf), and
// each disc sun's or sphere light's cone pdf where its cone holds d
// (docs/lights.md "Sampling"), mixed by the light selection probabilities
// (docs/mis.md eq. 3). Delta lights have no density here.
double light_direction_pdf(const WalkLights& lights, const glm::dvec3& o, const glm::dvec3& d);

// One light sample: a direction from the mixture of eq. (3) of docs/mis.md,
// or the direction toward a delta light with what it delivers.
struct LightPick {
  glm::dvec3 dir{0.0};
  int delta = -1;  // a delta light's index in WalkLights::analytic; −1: a direction of eq. (3)
  double t_max = std::numeric_limits<double>::infinity();  // delta: its distance (∞: a distant light)
  glm::dvec3 Li{0.0};  // delta: what reaches o without media, I·falloff/r² or E
};

// One light sample from vertex o: the environment map's 2D CDF, a point from an
// emissive grid's emission CDF and the direction toward it, a direction in a
// disc sun's or a sphere light's cone, or a delta light (docs/lights.md
// "Sampling"), picked with the selection's probabilities in that order.
// false: nothing drawn.
bool light_direction(const WalkLights& lights, const glm::dvec3& o, Pcg32& rng, LightPick& pick);

}  // namespace pyrolume::cpu
