#include "render/cpu/CpuRenderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "color/Blackbody.h"
#include "geometry/SceneSurfaces.h"
#include "geometry/Surfaces.h"
#include "light/AnalyticLights.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/Limits.h"
#include "render/LineEstimator.h"
#include "render/SceneChecks.h"
#include "render/cpu/Intersect.h"
#include "render/cpu/Media.h"
#include "render/cpu/Rng.h"
#include "render/cpu/Sampling.h"
#include "render/cpu/Transmittance.h"

namespace pyrolume {
namespace cpu {
namespace {

using Clock = std::chrono::steady_clock;

struct Scratch {
  std::vector<Span> spans;
  std::vector<double> cuts;
  std::vector<int> present;
  std::vector<double> rho;  // density looked up at the current collision, per present medium
  std::vector<double> lobe_w, lobe_g;  // the phase mixture at a scattering: σs_i/σs and g_i
  LeCache Le_cache;
  // The walk of a light ray runs inside the walk that sampled it and needs
  // scratch of its own.
  std::unique_ptr<Scratch> nested;
  Scratch& light_ray() {
    if (!nested) nested = std::make_unique<Scratch>();
    return *nested;
  }
};

// SIGINT/SIGTERM inside a pass (RenderControl::cancel): one path in a
// pathologically dense medium may take minutes of null collisions, so the
// flag is polled every kCancelPollSteps tracking steps (and samples), not only
// between passes, and the pass is abandoned by this exception.
struct PassCancelled {};
constexpr uint32_t kCancelPollSteps = 4096;

struct ThreadCounters {
  uint64_t collisions = 0;       // real collisions (absorption + scattering)
  uint64_t density_lookups = 0;  // trilinear density-texture samples
  uint64_t majorant_violations = 0;
  uint64_t nonfinite = 0;
  const std::atomic<bool>* cancel = nullptr;
  uint32_t until_poll = kCancelPollSteps;
  // One step of work (a tentative collision, a sample): throws PassCancelled
  // once the cancel flag is seen.
  void step() {
    if (--until_poll != 0) return;
    until_poll = kCancelPollSteps;
    if (cancel && cancel->load(std::memory_order_relaxed)) throw PassCancelled{};
  }
};

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

// What next-event estimation samples (host/light/LightSelection.h), and the
// analytic lights, which rays also meet (discs on escape, spheres on the way)
// whether they are sampled or not.
struct WalkLights {
  LightSelection selection;
  std::vector<const EmissionCdf*> cdf;  // per scene medium; null: not a light
  std::vector<AnalyticLight> analytic;  // per entry of Scene::lights (selection.p_light)
  bool active() const { return selection.strategy != LightStrategy::Bsdf; }
};

// Whether unit w lies in the cone of 1 − cos θ = omc around unit axis:
// |w − axis|² = 2(1 − cos α), which keeps the sun's 1e-5 (no 1 − cos).
bool in_cone(const glm::dvec3& w, const glm::dvec3& axis, double omc) {
  const glm::dvec3 e = w - axis;
  return glm::dot(e, e) <= 2.0 * omc;
}

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

// The closest sphere light along a ray with 0 < t < t_max. From inside a
// sphere the ray ends at its far side with nothing: it emits outward only.
struct SphereLightHit {
  int light = -1;  // index into WalkLights::analytic; −1: none
  double t = 0.0;
  bool outside = false;
};
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

// What every walk reads: the media, the surfaces, what escaping rays see, the
// lights and the integrator's settings.
struct WalkScene {
  const MediaData& md;
  const geometry::Surfaces& surfaces;
  const EnvironmentMap* environment;  // null: the constant background
  glm::dvec3 background;
  int max_depth;
  bool collision_estimator;
  const WalkLights& lights;
  bool transparent;  // film.transparent: the camera ray adds nothing where it escapes

  // Radiance of channel c seen by a ray escaping along d (camera and scattered
  // rays alike): the environment map replaces background.rgb (docs/scene-format.md "environment");
  // each disc sun whose cone holds d adds its radiance (docs/lights.md).
  double escaped(const glm::dvec3& d, int c) const {
    double L = environment ? environment->radiance(d)[c] : background[c];
    for (const AnalyticLight& l : lights.analytic)
      if (l.is_disc() && in_cone(d, l.light.direction, l.disc_omc)) L += l.disc_L[c];
    return L;
  }
};

// σa and σs of channel c at x, summed over the media present (s.present);
// s.rho keeps each one's density for the phase mixture and the emission.
void coefficients_at(const MediaData& md, int c, const glm::dvec3& x, Scratch& s, ThreadCounters& cnt,
                     double& sigma_a, double& sigma_s) {
  cnt.step();  // once per tentative collision, the unit every tracking loop advances by
  sigma_a = sigma_s = 0.0;
  s.rho.resize(s.present.size());
  for (size_t j = 0; j < s.present.size(); ++j) {
    const MediumData& m = md.media[s.present[j]];
    double rho = 1.0;
    if (m.is_vdb()) {
      rho = grid_density(m, x);
      ++cnt.density_lookups;
    }
    s.rho[j] = rho;
    sigma_a += m.sigma_a[c] * rho;
    sigma_s += m.sigma_s[c] * rho;
  }
}

// Σ σa_i Le_i of channel c at x over the media present (after coefficients_at).
double emitted_at(const MediaData& md, int c, const glm::dvec3& x, Scratch& s) {
  double e = 0.0;
  for (size_t j = 0; j < s.present.size(); ++j) {
    const int i = s.present[j];
    const MediumData& m = md.media[i];
    e += m.is_vdb() ? grid_sigma_a_Le(m, i, c, x, s.rho[j], s.Le_cache) : m.sigma_a_Le[c];
  }
  return e;
}

// The line estimator's second process (walk_channel), this reference's own
// rule, not the GPU's per-cell rates: in a grid medium a point every
// 1/kLinePointsPerVoxel voxels on average, over the whole medium; in a
// homogeneous one kLinePointsPerWidth across its smallest extent.
constexpr double kLinePointsPerVoxel = 0.25, kLinePointsPerWidth = 8.0;
double line_rate(const MediumData& m) {
  if (!m.is_vdb()) {
    const double width = m.bounds.smallest_extent();
    return width > 0.0 ? kLinePointsPerWidth / width : 0.0;
  }
  if (!m.volume || m.volume->density.grid.empty()) return 0.0;
  const glm::dmat4& to_world = m.volume->density.grid.index_to_world;
  const double voxel = std::min({glm::length(glm::dvec3(to_world[0])), glm::length(glm::dvec3(to_world[1])),
                                 glm::length(glm::dvec3(to_world[2]))});
  return voxel > 0.0 ? kLinePointsPerVoxel / voxel : 0.0;
}

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
double unidirectional_weight(const WalkLights& lights, const RayMis& mis) {
  if (!lights.active() || !(mis.pdf_dir > 0.0) || !(mis.p_light > 0.0)) return 1.0;
  if (lights.selection.strategy == LightStrategy::LightOnly) return 0.0;
  return power_heuristic(mis.pdf_dir, mis.p_light);
}

// The solid-angle pdf with which next_event at o picks direction d: the
// environment map's, for each emissive grid the pdf of the direction toward a
// point drawn from its emission CDF (EmissionCdf::direction_pdf), and each
// disc sun's or sphere light's cone pdf where its cone holds d (docs/lights.md
// "Sampling"), mixed by the light selection probabilities (docs/mis.md eq. 3).
// Delta lights have no density here.
double light_direction_pdf(const WalkScene& ws, const glm::dvec3& o, const glm::dvec3& d) {
  const WalkLights& lights = ws.lights;
  double p = 0.0;
  if (lights.selection.p_env > 0.0) p += lights.selection.p_env * ws.environment->pdf(d);
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

// The value f (BSDF·|cos| or phase function, channel c) and the solid-angle pdf
// with which the vertex's own sampling picks direction w.
struct VertexLobe {
  double f = 0.0, pdf = 0.0;
};

// A light ray (next_event) or a path: how the walk treats tentative collisions.
enum class WalkRole { Path, LightRay };

// film.aovs (docs/compositing.md "AOVs"): what a camera path's channel walk
// tells the layers and features. The walk's L splits at its first vertex:
// before_vertex (all of L when it has none) less direct (the background or
// sphere light the camera ray sees) is emission; direct is background; the
// rest is scatter or surface, by the first vertex's kind.
struct WalkAov {
  enum class Vertex { None, Medium, Surface } first_vertex = Vertex::None;
  double direct = 0.0, before_vertex = 0.0;
  // The camera ray's first event (a real collision, a surface, a sphere light).
  bool has_feature = false;
  double albedo = 0.0;  // this channel's
  glm::dvec3 normal{0.0};
  double depth = 0.0;
};

// camera_escaped: set when the walk's first ray (a camera ray) leaves the scene.
// aov: filled for a camera path (role Path) when given.
double walk_channel(const WalkScene& ws, int c, glm::dvec3 o, glm::dvec3 d, Pcg32& rng, ThreadCounters& cnt,
                    Scratch& s, int max_depth, WalkRole role = WalkRole::Path, bool* camera_escaped = nullptr,
                    WalkAov* aov = nullptr);

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
bool light_direction(const WalkScene& ws, const glm::dvec3& o, Pcg32& rng, LightPick& pick) {
  const WalkLights& lights = ws.lights;
  double u = rng.uniform();
  const double u_env = rng.uniform(), v_env = rng.uniform();
  const glm::dvec3 u3(rng.uniform(), rng.uniform(), rng.uniform());
  pick = LightPick{};
  if (u < lights.selection.p_env) {
    const EnvSample es = ws.environment->sample({u_env, v_env});
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

// The light ray toward a delta light (docs/lights.md "Sampling"): ratio-tracked
// like a light ray (docs/mis.md eq. 2a) but collecting nothing on its way, so it
// returns its transmittance W to distance t_max, or 0 when a surface or a
// sphere light comes first.
double delta_light_ray(const WalkScene& ws, int c, const glm::dvec3& o, const glm::dvec3& d, double t_max, Pcg32& rng,
                       ThreadCounters& cnt, Scratch& s) {
  if (!ws.surfaces.empty() && geometry::occluded(ws.surfaces, geometry::Ray{o, d}, t_max)) return 0.0;
  if (intersect_sphere_lights(ws.lights, o, d, t_max).light >= 0) return 0.0;
  ray_spans(ws.md, o, d, s.spans, s.cuts);
  double W = 1.0;
  for (size_t k = 0; k + 1 < s.cuts.size(); ++k) {
    const double a = s.cuts[k];
    if (!(a < t_max)) break;
    const double b = std::min(s.cuts[k + 1], t_max);
    const double sigma_maj = media_present(ws.md, s.spans, a, s.cuts[k + 1], c, s.present);
    if (!(sigma_maj > 0.0)) continue;
    for (double t = a;;) {
      t += sample_free_flight(sigma_maj, rng.uniform());
      if (!(t < b)) break;
      double sigma_a, sigma_s;
      coefficients_at(ws.md, c, o + t * d, s, cnt, sigma_a, sigma_s);
      if (exceeds_majorant(sigma_a + sigma_s, sigma_maj)) ++cnt.majorant_violations;
      W *= std::max(0.0, 1.0 - (sigma_a + sigma_s) / sigma_maj);
      if (W < kRatioTrackingRouletteBelow) {
        if (!(rng.uniform() < W)) return 0.0;
        W = 1.0;
      }
    }
  }
  return W;
}

// Next-event estimation from vertex o (the offset origin the continuing ray
// also uses): n light samples (light_direction). The radiance arriving along
// a direction of eq. (3) before anything scatters it is estimated by a light
// ray: the walk itself with max_depth 0, by ratio tracking. Each is weighted by the power
// heuristic for n samples of pdf p_light against the continuation's one
// sample of pdf p_m for the same direction, both in solid angle (Veach 1997
// eq. 9.13 with sample counts; docs/mis.md "Several light samples"). A delta
// light adds W·f·Li/(n·P_j), unweighted: nothing else finds it
// (docs/lights.md "Sampling").
// Returns the sum of radiance · f · w / (n · p_light), without the path weight β.
template <class Lobe>
double next_event(const WalkScene& ws, int c, const glm::dvec3& o, Lobe lobe, int n, Pcg32& rng, ThreadCounters& cnt,
                  Scratch& s) {
  const WalkLights& lights = ws.lights;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    LightPick pick;
    if (!light_direction(ws, o, rng, pick)) continue;
    const glm::dvec3 dir = pick.dir;
    const VertexLobe l = lobe(dir);
    if (!(l.f > 0.0)) continue;
    if (pick.delta >= 0) {
      if (!(pick.Li[c] > 0.0)) continue;
      const double W = delta_light_ray(ws, c, o, dir, pick.t_max, rng, cnt, s.light_ray());
      sum += l.f * W * pick.Li[c] / (n * lights.selection.p_light[pick.delta]);
      continue;
    }
    const double p_light = light_direction_pdf(ws, o, dir);
    if (!(p_light > 0.0)) continue;
    const double radiance = walk_channel(ws, c, o, dir, rng, cnt, s.light_ray(), 0, WalkRole::LightRay);
    const double w = lights.selection.strategy == LightStrategy::LightOnly
                         ? 1.0
                         : power_heuristic(n * p_light, lights.selection.continuation_pdf(l.pdf, p_light));
    sum += l.f * radiance * w / (n * p_light);
  }
  return sum;
}

// The direction the path leaves vertex o by: with lights, from the mixture
// p_m = c·p_vertex + (1 − c)·p_light (c = selection.p_continue_own), else from
// the vertex's own sampling (sample_own). weight = f/p_m; mis records p_m and
// n·p_light (n: the vertex's next-event samples) for the weights of what the
// ray finds. false: the direction carries nothing (below a surface).
template <class Lobe, class Own>
bool continue_from(const WalkScene& ws, const glm::dvec3& o, Lobe& lobe, Own sample_own, int n, Pcg32& rng,
                   glm::dvec3& d, double& weight, RayMis& mis) {
  if (!ws.lights.active()) {
    d = sample_own();
    const VertexLobe l = lobe(d);
    weight = l.pdf > 0.0 ? l.f / l.pdf : 0.0;
    mis = RayMis{l.pdf, 0.0};
    return l.f > 0.0;
  }
  LightPick pick;
  if (rng.uniform() < ws.lights.selection.p_continue_own) {
    d = sample_own();
  } else if (!light_direction(ws, o, rng, pick) || pick.delta >= 0) {
    // A delta light's direction has no density: the path ends there, so the
    // directions drawn have exactly the density p_m below.
    return false;
  } else {
    d = pick.dir;
  }
  const VertexLobe l = lobe(d);
  if (!(l.f > 0.0)) return false;
  const double p_light = light_direction_pdf(ws, o, d);
  const double p_m = ws.lights.selection.continuation_pdf(l.pdf, p_light);
  weight = l.f / p_m;
  mis = RayMis{p_m, n * p_light};
  return true;
}

// With next-event estimation, once the scatterings kept from absorption have
// lowered β below this fraction, Russian roulette (walk_channel; the GPU's
// SCATTER_ROULETTE_BELOW).
constexpr double kScatterRouletteBelow = 0.1;

// One random walk of a *grey* world: colour channel c alone.
//
// Chromatic σ and albedo: each RGB channel is rendered as its own grey world
// by an independent scalar walk (σa_c, σs_c, Le_c, albedo_c, background_c).
// Each walk is the textbook estimator of that channel's radiance, so the
// per-channel mean is unbiased trivially; the walks share only the camera ray,
// which does not bias a per-channel mean. (The GPU path instead tracks a
// max-channel majorant with spectral weights; keeping this one different is
// the point.)
//
// Each ray segment first finds the closest surface hit t_surf (Surfaces.h);
// media beyond it are irrelevant.
//
// Free flights: delta tracking (Woodcock et al. 1965) on [0, t_surf). Between
// consecutive bounds crossings the set of media is fixed and its majorant σ̄
// is the sum of their global majorants (Media.h); tentative collisions are
// sampled from σ̄ exp(−σ̄ t), restarting at each crossing and stopping at
// t_surf (the exponential is memoryless). At a tentative collision x one
// uniform u picks: absorption with probability σa(x)/σ̄, scattering with
// σs(x)/σ̄, a null collision with 1 − σt(x)/σ̄. Where only homogeneous media
// are present σt = σ̄ and this is the analog walk.
//
// Surfaces: no collision before t_surf ⇒ the path reaches the surface. Opaque,
// two-sided Lambertian: the new direction is cosine-distributed around the
// geometric normal flipped to the side the ray came from, n_f; f·cos θ/p =
// albedo, so the path weight β is multiplied by albedo_c(uv). The new ray
// starts at offset_ray_origin(p, n_f) so it cannot hit the surface it leaves.
// Surfaces do not emit.
//
// Emission estimators (integrator.emission_estimator), β the path weight
// (the product of the surface albedos met so far; without next-event
// estimation medium events keep it, their probabilities equal the
// coefficient ratios):
//  - "absorption": an absorbed path returns β · Le of the absorbing mixture,
//    Le = Σ σa_i Le_i / σa at x; escaping returns β · background.
//  - "collision" (pbrt-v4 §14.2, VolPathIntegrator: beta · σa · Le / σ_maj at
//    every majorant sample): at EVERY tentative collision add β Σ σa_i Le_i(x)/σ̄,
//    then absorb (end), scatter or continue; escaping adds β · background.
//  - "line" (docs/rendering.md "The line estimator"): the collision estimator,
//    plus a second Poisson process of rate ℓ = Σ line_rate of the media present
//    drawn between consecutive tentative collisions (where the walk is
//    certainly alive); every point of either process adds β Σ σa_i Le_i(x)/(σ̄ + ℓ).
// Scattering picks medium i's HG lobe with probability σs_i/σs (mixture phase
// function). Medium scatterings and surface bounces count together toward
// max_depth: the (max_depth+1)-th ends the path with nothing more (the
// absorption estimator returns 0, the collision estimator keeps what it
// collected before). Both count as real events.
//
// Next-event estimation (docs/mis.md), with the collision estimator only: at
// every scattering and surface vertex that max_depth allows, one light
// direction and a light ray along it (next_event, which runs this walk with
// max_depth 0); the continuation is drawn from the vertex's lobe or the lights
// (continue_from), and what its ray finds before the next real event (emission
// at tentative collisions, the environment on escape) is weighted by the power
// heuristic of the two direction pdfs (unidirectional_weight). A real
// collision then never absorbs where the mixture scatters: it scatters with β
// multiplied by σs/(σa + σs), and Russian roulette (kScatterRouletteBelow)
// ends paths that these factors have made faint (docs/mis.md "No absorption
// events").
//
// Light rays (role LightRay, max_depth 0) estimate the same integral
// I(y, ω) = ∫ T σa Le dt + T(∞) L_env by ratio tracking instead (Novák et al.
// 2014, with the collision estimator's terms): no event is chosen at a
// tentative collision, β is multiplied by its expectation there, the null
// fraction 1 − σt/σ̄, and Russian roulette ends the ray once
// β < kRatioTrackingRouletteBelow (survive with probability β, then β = 1), as
// in ratio_tracking_transmittance (Transmittance.h). E[Σ_k β_k σa Le(x_k)/σ̄] is the
// same integral as delta tracking's, without the noise of where the first
// real event falls (docs/mis.md "Light rays").
//
// Analytic lights (docs/lights.md "Analytic lights"): a sphere light ends any
// ray that meets it before a surface (media tracked up to it, as to a
// surface) and adds its radiance from outside; an escaping ray adds each disc
// sun whose cone holds it to the environment. Both are weighted by w_ray as
// the environment is (1 for camera rays). Delta lights only reach vertices
// through next_event.
double walk_channel(const WalkScene& ws, int c, glm::dvec3 o, glm::dvec3 d, Pcg32& rng, ThreadCounters& cnt,
                    Scratch& s, int max_depth, WalkRole role, bool* camera_escaped, WalkAov* aov) {
  if (role != WalkRole::Path) aov = nullptr;
  // The camera ray's first event (scatters == 0: o is still the camera).
  auto feature = [&](double albedo, const glm::dvec3& normal, double depth) {
    if (!aov || aov->has_feature) return;
    aov->has_feature = true;
    aov->albedo = albedo;
    aov->normal = normal;
    aov->depth = depth;
  };
  // The path's first vertex: the layers' split point.
  auto first_vertex = [&](double L_now, WalkAov::Vertex kind) {
    if (!aov || aov->first_vertex != WalkAov::Vertex::None) return;
    aov->first_vertex = kind;
    aov->before_vertex = L_now;
  };
  const MediaData& md = ws.md;
  const WalkLights& lights = ws.lights;
  const bool collision_estimator = ws.collision_estimator;
  const bool has_surfaces = !ws.surfaces.empty();
  int scatters = 0;
  double beta = 1.0;  // path weight: the surface albedos and, with NEE, the scattering albedos met so far
  double survival = 1.0;  // the factors σs/(σa + σs) of the scatterings kept from absorption, since the last roulette
  double L = 0.0;     // the collision estimator's running sum
  RayMis mis;         // the camera ray: never MIS-weighted
  const int n_surface = lights.selection.surface_light_samples;  // next-event samples per vertex
  const int n_medium = 1;
  // This segment was already collected by a ratio-tracked ray (ratio_tracked_continuation, below).
  bool skip_segment = false;
  for (;;) {
    // The closest surface bounds this segment.
    geometry::SurfaceHit hit;
    const bool hit_surface = has_surfaces && geometry::intersect(ws.surfaces, geometry::Ray{o, d},
                                                                 std::numeric_limits<double>::infinity(), hit);
    // A sphere light in front of it ends the segment instead (opaque).
    const SphereLightHit sphere = intersect_sphere_lights(
        lights, o, d, hit_surface ? hit.t : std::numeric_limits<double>::infinity());
    const double t_surf = sphere.light >= 0 ? sphere.t
                          : hit_surface     ? hit.t
                                            : std::numeric_limits<double>::infinity();

    // The weight of what this ray finds before its next event.
    const double w_ray = skip_segment ? 0.0 : unidirectional_weight(lights, mis);
    skip_segment = false;
    ray_spans(md, o, d, s.spans, s.cuts);
    bool scattered = false;
    for (size_t k = 0; k + 1 < s.cuts.size() && !scattered; ++k) {
      const double a = s.cuts[k];
      if (!(a < t_surf)) break;
      const double b = std::min(s.cuts[k + 1], t_surf);
      const double sigma_maj = media_present(md, s.spans, a, s.cuts[k + 1], c, s.present);
      if (!(sigma_maj > 0.0)) continue;
      // The line estimator's second process of collection points, of rate
      // line_rate; each point of either process collects 1/(σ̄ + line_rate).
      double line_rate = 0.0;
      if (collision_estimator)
        for (const int i : s.present) line_rate += md.media[i].line_rate;
      const double collect_rate = sigma_maj + line_rate;
      for (double t = a;;) {
        const double t_flight = t + sample_free_flight(sigma_maj, rng.uniform());
        // The path is alive on [t, t_flight): collect there.
        if (line_rate > 0.0 && w_ray > 0.0)
          for (double t_line = t + sample_free_flight(line_rate, rng.uniform()); t_line < std::min(t_flight, b);
               t_line += sample_free_flight(line_rate, rng.uniform())) {
            double sigma_a, sigma_s;
            coefficients_at(md, c, o + t_line * d, s, cnt, sigma_a, sigma_s);
            if (sigma_a > 0.0) L += beta * w_ray * emitted_at(md, c, o + t_line * d, s) / collect_rate;
          }
        t = t_flight;
        if (!(t < b)) break;  // memoryless: restart the flight at b
        const glm::dvec3 x = o + t * d;
        double sigma_a, sigma_s;
        coefficients_at(md, c, x, s, cnt, sigma_a, sigma_s);
        if (exceeds_majorant(sigma_a + sigma_s, sigma_maj)) ++cnt.majorant_violations;
        if (collision_estimator && sigma_a > 0.0) L += beta * w_ray * emitted_at(md, c, x, s) / collect_rate;
        if (role == WalkRole::LightRay) {
          beta *= std::max(0.0, 1.0 - (sigma_a + sigma_s) / sigma_maj);
          if (beta < kRatioTrackingRouletteBelow) {
            if (!(rng.uniform() < beta)) return L;
            beta = 1.0;
          }
          continue;
        }

        const double u = rng.uniform() * sigma_maj;
        // With next-event estimation a real collision scatters whenever the
        // mixture scatters at all (docs/mis.md "No absorption events"): the
        // collision estimator has collected the emission here already, and
        // β · σs/(σa + σs) keeps the expectation.
        const bool survive = lights.active() && collision_estimator && sigma_s > 0.0;
        if (scatters == 0 && u < sigma_a + sigma_s) feature(sigma_s / (sigma_a + sigma_s), glm::dvec3(0.0), t);
        if (!survive && u < sigma_a) {
          ++cnt.collisions;
          return collision_estimator ? L : beta * emitted_at(md, c, x, s) / sigma_a;
        }
        if (!(u < sigma_a + sigma_s)) continue;  // null collision
        ++cnt.collisions;
        if (scatters == max_depth) return collision_estimator ? L : 0.0;
        ++scatters;
        first_vertex(L, WalkAov::Vertex::Medium);
        if (survive) {
          // Russian roulette once these factors have lowered β below
          // kScatterRouletteBelow of what it was: survive with probability
          // survival / kScatterRouletteBelow, reweighted.
          const double r = sigma_s / (sigma_a + sigma_s);
          beta *= r;
          survival *= r;
          if (survival < kScatterRouletteBelow) {
            const double q = survival / kScatterRouletteBelow;
            if (!(rng.uniform() < q)) return L;
            beta /= q;
            survival = kScatterRouletteBelow;
          }
        }
        // The phase function of the mixture: Σ_i (σs_i/σs) HG(g_i).
        s.lobe_w.clear();
        s.lobe_g.clear();
        for (size_t j = 0; j < s.present.size(); ++j) {
          const MediumData& m = md.media[s.present[j]];
          const double ss = m.sigma_s[c] * s.rho[j];
          if (!(ss > 0.0)) continue;
          s.lobe_w.push_back(ss / sigma_s);
          s.lobe_g.push_back(m.g);
        }
        const glm::dvec3 d_in = d;
        auto phase = [&](const glm::dvec3& w) {
          double p = 0.0;
          for (size_t l = 0; l < s.lobe_w.size(); ++l) p += s.lobe_w[l] * hg_pdf(glm::dot(d_in, w), s.lobe_g[l]);
          return VertexLobe{p, p};  // sampled exactly: pdf = value
        };
        if (lights.active()) L += beta * next_event(ws, c, x, phase, n_medium, rng, cnt, s);
        // Given a scattering, u − σa is uniform on [0, σs) (u on [0, σa + σs)
        // when it survives absorption): reuse it to pick the lobe.
        double pick = survive ? u / (sigma_a + sigma_s) : (u - sigma_a) / sigma_s, g = 0.0;
        for (size_t l = 0; l < s.lobe_w.size(); ++l) {
          g = s.lobe_g[l];
          pick -= s.lobe_w[l];
          if (pick < 0.0) break;
        }
        o = x;
        double weight;
        if (!continue_from(ws, o, phase, [&] { return sample_hg(d_in, g, {rng.uniform(), rng.uniform()}).direction; },
                           n_medium, rng, d, weight, mis))
          return L;
        beta *= weight;
        scattered = true;
        break;
      }
    }
    if (scattered) continue;
    // A sphere light absorbs the ray and adds its radiance, weighted like the
    // environment's (docs/lights.md "Sampling"); black from inside.
    if (sphere.light >= 0) {
      const double seen = sphere.outside ? beta * w_ray * lights.analytic[sphere.light].value[c] : 0.0;
      if (scatters == 0 && aov) {
        const glm::dvec3 x = o + sphere.t * d;
        aov->direct = seen;
        feature(0.0, glm::normalize(x - lights.analytic[sphere.light].light.center), sphere.t);
      }
      return L + seen;
    }
    if (!hit_surface) {
      if (role == WalkRole::Path && scatters == 0) {  // the camera ray itself: alpha, transparency
        if (camera_escaped) *camera_escaped = true;
        if (ws.transparent) return L;
      }
      const double seen = beta * w_ray * ws.escaped(d, c);
      if (scatters == 0 && aov) aov->direct = seen;
      return L + seen;
    }

    // Reached the surface: a Lambertian bounce.
    ++cnt.collisions;
    const double albedo = geometry::albedo_at(ws.surfaces, hit)[c];
    const glm::dvec3 n_f = glm::dot(hit.normal, d) < 0.0 ? hit.normal : -hit.normal;
    if (scatters == 0) feature(albedo, n_f, hit.t);
    if (scatters == max_depth) return collision_estimator ? L : 0.0;
    ++scatters;
    first_vertex(L, WalkAov::Vertex::Surface);
    if (!(beta * albedo > 0.0)) return L;  // black surface: nothing more can arrive
    o = geometry::offset_ray_origin(hit.position, n_f);
    auto lambert = [&](const glm::dvec3& w) {
      const double cos_theta = std::max(0.0, glm::dot(n_f, w));
      return VertexLobe{albedo * cos_theta / std::numbers::pi, cos_theta / std::numbers::pi};
    };
    if (lights.active()) L += beta * next_event(ws, c, o, lambert, n_surface, rng, cnt, s);
    double weight;
    if (!continue_from(ws, o, lambert,
                       [&] { return sample_cosine_hemisphere(n_f, {rng.uniform(), rng.uniform()}).direction; },
                       n_surface, rng, d, weight, mis))
      return L;
    beta *= weight;
    if (lights.active() && lights.selection.ratio_tracked_continuation) {
      // docs/mis.md "Ratio-tracked continuation": what this ray would collect
      // before its next real event, I(o, d), comes from a light ray along d
      // with the continuation's weight and MIS weight; the path collects
      // nothing on that segment (emission or sky) and goes on as before.
      L += beta * unidirectional_weight(lights, mis) *
           walk_channel(ws, c, o, d, rng, cnt, s.light_ray(), 0, WalkRole::LightRay);
      skip_segment = true;
    }
  }
}

// film.aovs: one sample's three channel walks into a pixel's AOV sums
// (RenderResult::aov_sum's layout). L is the sample; recorded is false when
// it was not finite and was recorded as 0: then every layer adds 0. Each
// channel's walk is its own path, so each channel splits at its own first
// vertex. The features are
// averaged over the channel walks that have a first event: hits counts them
// in thirds (for surfaces and grey media every channel has the same chance).
void add_sample_aovs(const glm::dvec3& L, bool recorded, const WalkAov aov[3], double* sum) {
  for (int c = 0; c < 3; ++c) {
    const WalkAov& a = aov[c];
    if (recorded) {
      const double before = a.first_vertex == WalkAov::Vertex::None ? L[c] : a.before_vertex;
      sum[kAovEmission + c] += before - a.direct;
      sum[kAovBackground + c] += a.direct;
      sum[(a.first_vertex == WalkAov::Vertex::Surface ? kAovSurface : kAovScatter) + c] += L[c] - before;
    }
    if (!a.has_feature) continue;
    sum[kAovAlbedo + c] += a.albedo;
    for (int k = 0; k < 3; ++k) sum[kAovNormal + k] += a.normal[k] / 3.0;
    sum[kAovDepth] += a.depth / 3.0;
    sum[kAovHits] += 1.0 / 3.0;
  }
}

// The media part of the guide: emission and transmittance along the spans
// in s (ray_spans) up to t_end.
constexpr double kGuideMinTransmittance = 1e-6;
void guide_media(const WalkScene& ws, const glm::dvec3& o, const glm::dvec3& d, double t_end, Scratch& s,
                 glm::dvec3& L, glm::dvec3& T) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double h = inf;  // ray parameter per density texel, the finest grid's
  for (const Span& sp : s.spans) {
    const MediumData& m = ws.md.media[sp.medium];
    if (!m.is_vdb()) continue;
    const glm::dvec3 du(m.volume->density.grid.world_to_index * glm::dvec4(d, 0.0));
    h = std::min(h, 1.0 / std::max(glm::length(du), 1e-300));
  }
  for (size_t k = 0; k + 1 < s.cuts.size(); ++k) {
    const double a = s.cuts[k], b = std::min(s.cuts[k + 1], t_end);
    if (!(b > a)) break;
    media_present(ws.md, s.spans, a, b, 0, s.present);
    if (s.present.empty()) continue;
    bool vdb = false;
    for (int i : s.present) vdb = vdb || ws.md.media[i].is_vdb();
    const double steps = vdb ? std::ceil((b - a) / h) : 1.0;
    const int n = int(std::clamp(steps, 1.0, 1e6));
    const double dt = (b - a) / n;
    for (int j = 0; j < n; ++j) {
      const glm::dvec3 x = o + d * (a + (j + 0.5) * dt);
      glm::dvec3 sigma_t(0.0), E(0.0);
      for (int i : s.present) {
        const MediumData& m = ws.md.media[i];
        const double rho = m.is_vdb() ? grid_density(m, x) : 1.0;
        for (int c = 0; c < 3; ++c) {
          sigma_t[c] += (m.sigma_a[c] + m.sigma_s[c]) * rho;
          E[c] += m.is_vdb() ? grid_sigma_a_Le(m, i, c, x, rho, s.Le_cache) : m.sigma_a_Le[c];
        }
      }
      for (int c = 0; c < 3; ++c) {
        const double tr = std::exp(-sigma_t[c] * dt);
        L[c] += T[c] * (sigma_t[c] * dt > 1e-4 ? E[c] * (1.0 - tr) / sigma_t[c] : E[c] * dt);
        T[c] *= tr;
      }
      // Nothing behind this adds more than 1e-6 of its own light (the GPU's
      // GUIDE_MIN_TRANSMITTANCE).
      if (std::max({T.x, T.y, T.z}) < kGuideMinTransmittance) return;
    }
  }
}

// The denoiser's guide along a camera ray (film.aovs; docs/compositing.md
// "Denoiser"; the GPU's shaders/guide.glsl is written apart from this): what
// the ray sees unscattered, without random numbers. The media's emission
// ∫ T σaLe dt up to the first surface or sphere light, by a midpoint ray
// march: steps of at most one density texel where a vdb medium is present (a
// segment with homogeneous media only is one step), each exact for constant
// coefficients, L += T·E/σt·(1 − e^(−σt·Δt)), T ·= e^(−σt·Δt). Then T times
// what ends the ray: a sphere light's radiance (from outside), the
// background unless film.transparent, nothing at a surface; T is 0 at a
// surface or sphere light, as alpha is 1 there.
void guide_march(const WalkScene& ws, const glm::dvec3& o, const glm::dvec3& d, Scratch& s, glm::dvec3& L,
                 glm::dvec3& T) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  L = glm::dvec3(0.0);
  T = glm::dvec3(1.0);
  geometry::SurfaceHit hit;
  const bool surface = !ws.surfaces.empty() && geometry::intersect(ws.surfaces, geometry::Ray{o, d}, inf, hit);
  const SphereLightHit sphere = intersect_sphere_lights(ws.lights, o, d, surface ? hit.t : inf);
  const double t_end = sphere.light >= 0 ? sphere.t : surface ? hit.t : inf;
  ray_spans(ws.md, o, d, s.spans, s.cuts);
  guide_media(ws, o, d, t_end, s, L, T);
  if (sphere.light >= 0) {
    if (sphere.outside) L += T * ws.lights.analytic[sphere.light].value;
    T = glm::dvec3(0.0);
  } else if (surface) {
    T = glm::dvec3(0.0);
  } else if (!ws.transparent) {
    for (int c = 0; c < 3; ++c) L[c] += T[c] * ws.escaped(d, c);
  }
}

}  // namespace

glm::dvec3 camera_ray_direction(const Camera& camera, int width, int height, double fx, double fy) {
  glm::dvec3 forward = glm::normalize(camera.look_at - camera.position);
  glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  glm::dvec3 up = glm::cross(right, forward);
  double tan_half = std::tan(0.5 * camera.fov_deg * std::numbers::pi / 180.0);
  double aspect = double(width) / double(height);
  double sx = (2.0 * fx / width - 1.0) * tan_half * aspect;
  double sy = (1.0 - 2.0 * fy / height) * tan_half;
  return glm::normalize(forward + sx * right + sy * up);
}

namespace {

// The pixel's guide (RenderResult::aov_sum at kAovGuide, kAovGuideAlpha): the
// mean of four marches through the centres of the pixel's 2×2 quarters, once
// per render (docs/compositing.md "The guide").
void pixel_guide(const WalkScene& ws, const Camera& camera, int W, int H, int x, int y, Scratch& s,
                 double* aov_sum) {
  glm::dvec3 sum_L(0.0);
  double sum_alpha = 0.0;
  for (int j = 0; j < 4; ++j) {
    const double fx = x + 0.25 + 0.5 * (j & 1), fy = y + 0.25 + 0.5 * (j >> 1);
    glm::dvec3 L, T;
    guide_march(ws, camera.position, camera_ray_direction(camera, W, H, fx, fy), s, L, T);
    sum_L += L;
    sum_alpha += 1.0 - (T.x + T.y + T.z) / 3.0;
  }
  for (int c = 0; c < 3; ++c) aov_sum[kAovGuide + c] = sum_L[c] / 4.0;
  aov_sum[kAovGuideAlpha] = sum_alpha / 4.0;
}

}  // namespace

}  // namespace cpu

namespace {

// The CPU's AccumulationState layout (host byte order): Σ L and Σ L² as
// doubles (width·height·3 each), then the counters collisions, density
// lookups and non-finite samples as uint64.
struct CpuCounters {
  uint64_t collisions = 0, density_lookups = 0, nonfinite = 0;
};

AccumulationState save_state(const RenderResult& res, const CpuCounters& c) {
  AccumulationState st;
  st.backend = "cpu";
  st.width = res.width;
  st.height = res.height;
  st.spp = res.spp;
  const size_t n = res.sum.size() * sizeof(double), na = res.alpha_sum.size() * sizeof(double);
  st.data.resize(2 * n + 2 * na + sizeof c);
  std::memcpy(st.data.data(), res.sum.data(), n);
  std::memcpy(st.data.data() + n, res.sum_sq.data(), n);
  std::memcpy(st.data.data() + 2 * n, res.alpha_sum.data(), na);
  std::memcpy(st.data.data() + 2 * n + na, res.alpha_sum_sq.data(), na);
  std::memcpy(st.data.data() + 2 * n + 2 * na, &c, sizeof c);
  return st;
}

void load_state(const AccumulationState& st, RenderResult& res, CpuCounters& c) {
  const size_t n = res.sum.size() * sizeof(double);
  if (st.backend != "cpu" || st.width != res.width || st.height != res.height ||
      st.data.size() != CpuRenderer::accumulation_bytes(res.width, res.height))
    throw std::invalid_argument("cpu reference: the resumed accumulation is not a " + std::to_string(res.width) + "x" +
                                std::to_string(res.height) + " cpu one");
  const size_t na = res.alpha_sum.size() * sizeof(double);
  std::memcpy(res.sum.data(), st.data.data(), n);
  std::memcpy(res.sum_sq.data(), st.data.data() + n, n);
  std::memcpy(res.alpha_sum.data(), st.data.data() + 2 * n, na);
  std::memcpy(res.alpha_sum_sq.data(), st.data.data() + 2 * n + na, na);
  std::memcpy(&c, st.data.data() + 2 * n + 2 * na, sizeof c);
  res.spp = res.resumed_spp = st.spp;
}

}  // namespace

uint64_t CpuRenderer::accumulation_bytes(int width, int height) {
  return uint64_t(width) * uint64_t(height) * 8 * sizeof(double) + sizeof(CpuCounters);
}

uint64_t CpuRenderer::nonfinite_sums(const AccumulationState& state) {
  const size_t sums = size_t(state.width) * size_t(state.height) * 8;  // the doubles before the counters
  if (state.data.size() < sums * sizeof(double)) throw std::logic_error("cpu reference: accumulation too short");
  uint64_t count = 0;
  for (size_t i = 0; i < sums; ++i) {
    double v;
    std::memcpy(&v, state.data.data() + i * sizeof v, sizeof v);
    count += !std::isfinite(v);
  }
  return count;
}

CpuRenderer::CpuRenderer(int threads) {
  if (threads <= 0) threads = int(std::thread::hardware_concurrency());
  threads_ = std::max(1, threads);
}

std::string CpuRenderer::device_name() const {
  return "CPU reference (" + std::to_string(threads_) + (threads_ == 1 ? " thread)" : " threads)");
}

RenderResult CpuRenderer::render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) {
  using namespace cpu;
  auto load_start = Clock::now();
  if (settings.width <= 0 || settings.height <= 0 || !spp_in_range(settings.spp))
    throw std::invalid_argument("cpu reference: width, height and spp must be positive (spp at most 2^24)");
  {
    glm::dvec3 f = scene.camera.look_at - scene.camera.position;
    if (!(glm::length(glm::cross(f, scene.camera.up)) > 0.0))
      throw std::invalid_argument("cpu reference: camera up is parallel to the view direction");
  }
  // Σ L, Σ L², Σα and Σα² in double, the pass being accumulated beside them,
  // and one copy of them for a checkpoint.
  check_accumulation_fits_memory(scene.file.string(), settings.width, settings.height, 3 * 8 * sizeof(double));
  check_scene_ranges(scene);
  MediaData media = prepare_media(scene);  // loads the vdb media's grids
  for (size_t i = 0; i < media.media.size(); ++i)
    if (media.media[i].volume) check_loaded_medium(scene, i, *media.media[i].volume);
  const geometry::Surfaces surfaces = geometry::build_surfaces(scene);  // meshes, textures, BVH
  std::optional<EnvironmentMap> environment;
  if (scene.environment)
    environment = EnvironmentMap::load(scene.environment->file, scene.environment->scale,
                                       scene.environment->rotation_deg,
                                       scene.up_axis.value_or(UpAxis::Z) == UpAxis::Y);

  const int W = settings.width, H = settings.height;
  const int max_depth = std::max(0, scene.integrator.max_depth);
  // Lights for next-event estimation: the environment map and every grid
  // medium that emits (its emission CDF over the grid as stored), where the
  // scene may sample them (light_candidates). The selection also resolves the
  // emission estimator ("auto"), as it does for the Vulkan backend.
  std::vector<std::optional<EmissionCdf>> cdfs(scene.media.size());
  WalkLights lights;
  lights.cdf.assign(scene.media.size(), nullptr);
  if (light_candidates(scene).media)
    for (size_t i = 0; i < scene.media.size(); ++i)
      if (media.media[i].is_vdb() && media.media[i].volume && scene.media[i].emission.emits()) {
        cdfs[i] = EmissionCdf::build_light(scene.media[i], *media.media[i].volume);
        if (!cdfs[i]->empty()) lights.cdf[i] = &*cdfs[i];
      }
  // The media the line estimator collects (the file's "line", or "auto"'s choice).
  std::vector<const StoredVolume*> volumes(scene.media.size(), nullptr);
  for (size_t i = 0; i < scene.media.size(); ++i) volumes[i] = media.media[i].volume.get();
  const LineMedia line = line_media(scene, volumes);
  lights.selection = select_lights(scene, environment ? &*environment : nullptr, lights.cdf, line.any());
  for (size_t i = 0; i < scene.media.size(); ++i)
    if (line.line[i]) media.media[i].line_rate = line_rate(media.media[i]);
  for (const Light& l : scene.lights) {
    AnalyticLight a;
    a.light = l;
    a.light.direction = glm::normalize(l.direction);
    a.value = light_value(l);
    if (l.type == Light::Type::Distant) {
      a.disc_omc = disc_one_minus_cos(l);
      a.disc_L = disc_radiance(l);
    }
    if (l.type == Light::Type::Spot) a.cone = spot_cone(l);
    lights.analytic.push_back(a);
  }
  const bool collision_estimator = lights.selection.estimator != EmissionEstimator::Absorption;
  const WalkScene walk_scene{media,     surfaces,           environment ? &*environment : nullptr, scene.background,
                             max_depth, collision_estimator, lights, scene.film.transparent};
  RenderResult res;
  res.warnings = media.warnings;  // the CLI prints them ("pyrolume: warning: ...")
  res.width = W;
  res.height = H;
  res.backend = name();
  res.device = device_name();
  res.light_strategy = strategy_name(lights.selection.strategy);
  res.emission_estimator = to_string(lights.selection.estimator);
  res.spp_target = settings.spp;
  res.sum.assign(size_t(W) * H * 3, 0.0);
  res.sum_sq.assign(size_t(W) * H * 3, 0.0);
  res.alpha_sum.assign(size_t(W) * H, 0.0);
  res.alpha_sum_sq.assign(size_t(W) * H, 0.0);
  if (settings.aovs) res.aov_sum.assign(size_t(W) * H * kAovValues, 0.0);
  // Resumed: the sums continue in sample order, so the result is bit-identical
  // to an uninterrupted render's (per-pixel sums never depend on passes).
  CpuCounters totals;
  if (control.resume) load_state(*control.resume, res, totals);

  constexpr int kTile = 16;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int n_tiles = tiles_x * tiles_y;
  const int n_threads = std::min(threads_, n_tiles);
  auto render_start = Clock::now();
  res.load_seconds = std::chrono::duration<double>(render_start - load_start).count();

  uint64_t total_violations = 0;
  auto last_checkpoint = render_start;
  int spp_done = res.spp;
  // A pass accumulates into `next` (the sums so far plus its samples, added in
  // sample order as before, so results are bit-identical) and is swapped in
  // only when complete: a pass abandoned by a signal leaves res as the passes
  // before it made it.
  std::vector<double> next_sum(res.sum.size()), next_sum_sq(res.sum_sq.size());
  std::vector<double> next_alpha(res.alpha_sum.size()), next_alpha_sq(res.alpha_sum_sq.size());
  std::vector<double> next_aov(res.aov_sum.size());
  while (spp_done < settings.spp) {
    const int s_begin = spp_done, s_end = std::min(settings.spp, spp_done + kPassSpp);
    std::atomic<int> next_tile{0};
    std::atomic<bool> abandoned{false};
    std::vector<ThreadCounters> counters(n_threads);
    // The pass's tiles, taken from a shared counter until none are left.
    auto render_tiles = [&](ThreadCounters& cnt, Scratch& scratch) {
      for (int tile; !abandoned.load(std::memory_order_relaxed) && (tile = next_tile.fetch_add(1)) < n_tiles;) {
        int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
        for (int y = y0; y < std::min(H, y0 + kTile); ++y)
          for (int x = x0; x < std::min(W, x0 + kTile); ++x) {
            size_t pix = size_t(y) * W + x;
            double sum[3], sum_sq[3];
            for (int c = 0; c < 3; ++c) {
              sum[c] = res.sum[pix * 3 + c];
              sum_sq[c] = res.sum_sq[pix * 3 + c];
            }
            double alpha_sum = res.alpha_sum[pix], alpha_sq = res.alpha_sum_sq[pix];
            double aov_sum[kAovValues] = {};
            if (settings.aovs) std::copy_n(res.aov_sum.data() + pix * kAovValues, kAovValues, aov_sum);
            if (settings.aovs && s_begin == 0) pixel_guide(walk_scene, scene.camera, W, H, x, y, scratch, aov_sum);
            for (int si = s_begin; si < s_end; ++si) {
              cnt.step();
              Pcg32 rng = Pcg32::for_sample(settings.seed, settings.frame, pix, uint64_t(si));
              // Box filter: a uniform point in the pixel.
              double fx = x + rng.uniform(), fy = y + rng.uniform();
              glm::dvec3 dir = camera_ray_direction(scene.camera, W, H, fx, fy);
              glm::dvec3 L;
              // Alpha (docs/compositing.md): each channel's walk is a grey delta
              // tracker whose camera ray escapes with probability T_c, so
              // 1 − (escapes)/3 has mean 1 − avg_c T_c.
              int escapes = 0;
              WalkAov aov[3];
              for (int c = 0; c < 3; ++c) {
                bool escaped = false;
                L[c] = walk_channel(walk_scene, c, scene.camera.position, dir, rng, cnt, scratch, max_depth,
                                    WalkRole::Path, &escaped, settings.aovs ? &aov[c] : nullptr);
                escapes += escaped ? 1 : 0;
              }
              const double alpha = 1.0 - escapes / 3.0;
              alpha_sum += alpha;
              alpha_sq += alpha * alpha;
              // NaN, Inf and beyond MAX_SAMPLE_RADIANCE (where float sums of
              // squares could overflow): recorded as 0, counted in nonfinite_samples.
              const double kMaxL = kMaxSampleRadiance;
              const bool recorded = std::abs(L.x) <= kMaxL && std::abs(L.y) <= kMaxL && std::abs(L.z) <= kMaxL;
              if (!recorded) {
                ++cnt.nonfinite;
                L = glm::dvec3(0.0);
              }
              for (int c = 0; c < 3; ++c) {
                sum[c] += L[c];
                sum_sq[c] += L[c] * L[c];
              }
              if (settings.aovs) add_sample_aovs(L, recorded, aov, aov_sum);
            }
            if (settings.aovs) std::copy_n(aov_sum, kAovValues, next_aov.data() + pix * kAovValues);
            for (int c = 0; c < 3; ++c) {
              next_sum[pix * 3 + c] = sum[c];
              next_sum_sq[pix * 3 + c] = sum_sq[c];
            }
            next_alpha[pix] = alpha_sum;
            next_alpha_sq[pix] = alpha_sq;
          }
      }
    };
    auto worker = [&](int tid) {
      Scratch scratch;
      ThreadCounters& cnt = counters[tid];
      cnt.cancel = control.cancel;
      try {
        render_tiles(cnt, scratch);
      } catch (const PassCancelled&) {
        abandoned = true;  // the other threads stop at their next poll or tile
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < n_threads; ++t) pool.emplace_back(worker, t);
    worker(0);
    for (auto& th : pool) th.join();
    if (abandoned) {  // interrupted within the pass: it never happened
      res.cancelled = true;
      break;
    }
    res.sum.swap(next_sum);
    res.sum_sq.swap(next_sum_sq);
    res.alpha_sum.swap(next_alpha);
    res.alpha_sum_sq.swap(next_alpha_sq);
    res.aov_sum.swap(next_aov);
    for (const auto& cnt : counters) {
      totals.collisions += cnt.collisions;
      totals.nonfinite += cnt.nonfinite;
      totals.density_lookups += cnt.density_lookups;
      total_violations += cnt.majorant_violations;
    }

    spp_done = s_end;
    res.spp = spp_done;
    if (control.progress) control.progress(spp_done, settings.spp);
    if (spp_done >= settings.spp) break;
    if (control.checkpoint && control.checkpoint_seconds > 0.0 &&
        std::chrono::duration<double>(Clock::now() - last_checkpoint).count() >= control.checkpoint_seconds) {
      control.checkpoint(save_state(res, totals));
      last_checkpoint = Clock::now();
    }
    if (control.cancel && control.cancel->load()) {
      res.cancelled = true;
      break;
    }
    if (settings.time_limit > 0.0 &&
        std::chrono::duration<double>(Clock::now() - render_start).count() > settings.time_limit)
      break;
  }
  res.seconds = std::chrono::duration<double>(Clock::now() - render_start).count();
  // Both counters are summed over camera samples of the average over the three
  // channel walks (each walk's count, all three added, divided by 3):
  //  - events: real collisions (absorptions + scatterings) and surface
  //    bounces, including the one that max_depth ends;
  //  - density_lookups: trilinear density-texture samples, one per vdb medium
  //    present at each tentative collision (real or null); homogeneous media
  //    read no texture. (Shadow rays, when MIS lands, add their ratio-tracking
  //    lookups the same way.) Temperature lookups are not counted.
  res.events = double(totals.collisions) / 3.0;
  res.density_lookups = double(totals.density_lookups) / 3.0;
  majorant_violations_ = total_violations;
  if (total_violations)
    std::fprintf(stderr, "warning: cpu reference: %llu tentative collisions had sigma_t above the majorant\n",
                 (unsigned long long)total_violations);
  res.nonfinite_samples = totals.nonfinite;
  if (res.spp < settings.spp) res.state = save_state(res, totals);
  return res;
}

}  // namespace pyrolume
