#include "render/cpu/Walk.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "geometry/SceneSurfaces.h"
#include "render/cpu/Intersect.h"
#include "render/cpu/Sampling.h"
#include "render/cpu/Transmittance.h"

namespace pyrolume::cpu {

MediumCoefficients coefficients_at(const MediaData& md, int c, const glm::dvec3& x, Scratch& s, ThreadCounters& cnt) {
  cnt.step();  // once per tentative collision, the unit every tracking loop advances by
  MediumCoefficients k;
  s.rho.resize(s.present.size());
  for (size_t j = 0; j < s.present.size(); ++j) {
    const MediumData& m = md.media[s.present[j]];
    double rho = 1.0;
    if (m.is_vdb()) {
      rho = grid_density(m, x);
      ++cnt.density_lookups;
    }
    s.rho[j] = rho;
    k.sigma_a += m.sigma_a[c] * rho;
    k.sigma_s += m.sigma_s[c] * rho;
  }
  return k;
}

double emitted_at(const MediaData& md, int c, const glm::dvec3& x, Scratch& s) {
  double e = 0.0;
  for (size_t j = 0; j < s.present.size(); ++j) {
    const int i = s.present[j];
    const MediumData& m = md.media[i];
    e += m.is_vdb() ? grid_sigma_a_Le(m, i, c, x, s.rho[j], s.Le_cache) : m.sigma_a_Le[c];
  }
  return e;
}

namespace {

// The value f (BSDF·|cos| or phase function, channel c) and the solid-angle pdf
// with which the vertex's own sampling picks direction w.
struct VertexLobe {
  double f = 0.0, pdf = 0.0;
};

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
      const auto [sigma_a, sigma_s] = coefficients_at(ws.md, c, o + t * d, s, cnt);
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
    if (!light_direction(ws.lights, o, rng, pick)) continue;
    const glm::dvec3 dir = pick.dir;
    const VertexLobe l = lobe(dir);
    if (!(l.f > 0.0)) continue;
    if (pick.delta >= 0) {
      if (!(pick.Li[c] > 0.0)) continue;
      const double W = delta_light_ray(ws, c, o, dir, pick.t_max, rng, cnt, s.light_ray());
      sum += l.f * W * pick.Li[c] / (n * lights.selection.p_light[pick.delta]);
      continue;
    }
    const double p_light = light_direction_pdf(ws.lights, o, dir);
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
  } else if (!light_direction(ws.lights, o, rng, pick) || pick.delta >= 0) {
    // A delta light's direction has no density: the path ends there, so the
    // directions drawn have exactly the density p_m below.
    return false;
  } else {
    d = pick.dir;
  }
  const VertexLobe l = lobe(d);
  if (!(l.f > 0.0)) return false;
  const double p_light = light_direction_pdf(ws.lights, o, d);
  const double p_m = ws.lights.selection.continuation_pdf(l.pdf, p_light);
  weight = l.f / p_m;
  mis = RayMis{p_m, n * p_light};
  return true;
}

// With next-event estimation, once the scatterings kept from absorption have
// lowered β below this fraction, Russian roulette (walk_channel; the GPU's
// SCATTER_ROULETTE_BELOW).
constexpr double kScatterRouletteBelow = 0.1;

// How the media along the current ray left the walk.
enum class Flight { Scattered, Ended, Reached };  // Reached: no real event before the segment's end

// One channel walk under way: what walk_channel's parts share.
struct Walk {
  const WalkScene& ws;
  const int c;
  Pcg32& rng;
  ThreadCounters& cnt;
  Scratch& s;
  const int max_depth;
  const WalkRole role;
  bool* const camera_escaped;
  WalkAov* const aov;  // null unless a camera path's
  glm::dvec3 o, d;     // the current ray
  int scatters = 0;
  double beta = 1.0;  // path weight: the surface albedos and, with NEE, the scattering albedos met so far
  double survival = 1.0;  // the factors σs/(σa + σs) of the scatterings kept from absorption, since the last roulette
  double L = 0.0;     // the collision estimator's running sum
  RayMis mis;         // the camera ray: never MIS-weighted
  // This segment was already collected by a ratio-tracked ray (ratio_tracked_continuation, surface_bounce).
  bool skip_segment = false;
  double result = 0.0;  // what the walk returns, once a part says it has ended

  Walk(const WalkScene& ws, int c, Pcg32& rng, ThreadCounters& cnt, Scratch& s, int max_depth, WalkRole role,
       bool* camera_escaped, WalkAov* aov, const glm::dvec3& o, const glm::dvec3& d)
      : ws(ws), c(c), rng(rng), cnt(cnt), s(s), max_depth(max_depth), role(role), camera_escaped(camera_escaped),
        aov(aov), o(o), d(d) {}

  // The camera ray's first event (scatters == 0: o is still the camera).
  void feature(double albedo, const glm::dvec3& normal, double depth) {
    if (!aov || aov->has_feature) return;
    aov->has_feature = true;
    aov->albedo = albedo;
    aov->normal = normal;
    aov->depth = depth;
  }
  // The path's first vertex: the layers' split point.
  void first_vertex(WalkAov::Vertex kind) {
    if (!aov || aov->first_vertex != WalkAov::Vertex::None) return;
    aov->first_vertex = kind;
    aov->before_vertex = L;
  }
  // The walk ends with value: false for the parts that say whether it goes
  // on, Flight::Ended for the media's.
  bool end(double value) {
    result = value;
    return false;
  }
  Flight ended(double value) {
    result = value;
    return Flight::Ended;
  }
};

// A real scattering at x, u the uniform on [0, σ̄) that chose it: the phase
// function of the mixture, next-event estimation, and the direction the path
// goes on in. Ended: max_depth, roulette or a direction that carries nothing.
Flight scatter_at(Walk& w, const glm::dvec3& x, double u, double sigma_a, double sigma_s, bool survive) {
  const MediaData& md = w.ws.md;
  Scratch& s = w.s;
  const int c = w.c;
  if (w.scatters == w.max_depth) return w.ended(w.ws.collision_estimator ? w.L : 0.0);
  ++w.scatters;
  w.first_vertex(WalkAov::Vertex::Medium);
  if (survive) {
    // Russian roulette once these factors have lowered β below
    // kScatterRouletteBelow of what it was: survive with probability
    // survival / kScatterRouletteBelow, reweighted.
    const double r = sigma_s / (sigma_a + sigma_s);
    w.beta *= r;
    w.survival *= r;
    if (w.survival < kScatterRouletteBelow) {
      const double q = w.survival / kScatterRouletteBelow;
      if (!(w.rng.uniform() < q)) return w.ended(w.L);
      w.beta /= q;
      w.survival = kScatterRouletteBelow;
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
  const glm::dvec3 d_in = w.d;
  auto phase = [&](const glm::dvec3& dir) {
    double p = 0.0;
    for (size_t l = 0; l < s.lobe_w.size(); ++l) p += s.lobe_w[l] * hg_pdf(glm::dot(d_in, dir), s.lobe_g[l]);
    return VertexLobe{p, p};  // sampled exactly: pdf = value
  };
  constexpr int n_medium = 1;  // next-event samples per medium vertex
  if (w.ws.lights.active()) w.L += w.beta * next_event(w.ws, c, x, phase, n_medium, w.rng, w.cnt, s);
  // Given a scattering, u − σa is uniform on [0, σs) (u on [0, σa + σs)
  // when it survives absorption): reuse it to pick the lobe.
  double pick = survive ? u / (sigma_a + sigma_s) : (u - sigma_a) / sigma_s, g = 0.0;
  for (size_t l = 0; l < s.lobe_w.size(); ++l) {
    g = s.lobe_g[l];
    pick -= s.lobe_w[l];
    if (pick < 0.0) break;
  }
  w.o = x;
  double weight;
  Pcg32& rng = w.rng;
  if (!continue_from(w.ws, w.o, phase, [&] { return sample_hg(d_in, g, {rng.uniform(), rng.uniform()}).direction; },
                     n_medium, rng, w.d, weight, w.mis))
    return w.ended(w.L);
  w.beta *= weight;
  return Flight::Scattered;
}

// Free flights through the media along the current ray up to t_surf: delta
// tracking (or ratio tracking for a light ray), the emission the estimator
// collects on the way with weight w_ray, and the first real event.
Flight track_media(Walk& w, double t_surf, double w_ray) {
  const MediaData& md = w.ws.md;
  Scratch& s = w.s;
  const int c = w.c;
  const bool collision_estimator = w.ws.collision_estimator;
  ray_spans(md, w.o, w.d, s.spans, s.cuts);
  for (size_t k = 0; k + 1 < s.cuts.size(); ++k) {
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
      const double t_flight = t + sample_free_flight(sigma_maj, w.rng.uniform());
      // The path is alive on [t, t_flight): collect there.
      if (line_rate > 0.0 && w_ray > 0.0)
        for (double t_line = t + sample_free_flight(line_rate, w.rng.uniform()); t_line < std::min(t_flight, b);
             t_line += sample_free_flight(line_rate, w.rng.uniform())) {
          const glm::dvec3 x_line = w.o + t_line * w.d;
          if (coefficients_at(md, c, x_line, s, w.cnt).sigma_a > 0.0)
            w.L += w.beta * w_ray * emitted_at(md, c, x_line, s) / collect_rate;
        }
      t = t_flight;
      if (!(t < b)) break;  // memoryless: restart the flight at b
      const glm::dvec3 x = w.o + t * w.d;
      const auto [sigma_a, sigma_s] = coefficients_at(md, c, x, s, w.cnt);
      if (exceeds_majorant(sigma_a + sigma_s, sigma_maj)) ++w.cnt.majorant_violations;
      if (collision_estimator && sigma_a > 0.0) w.L += w.beta * w_ray * emitted_at(md, c, x, s) / collect_rate;
      if (w.role == WalkRole::LightRay) {
        w.beta *= std::max(0.0, 1.0 - (sigma_a + sigma_s) / sigma_maj);
        if (w.beta < kRatioTrackingRouletteBelow) {
          if (!(w.rng.uniform() < w.beta)) return w.ended(w.L);
          w.beta = 1.0;
        }
        continue;
      }
      const double u = w.rng.uniform() * sigma_maj;
      // With next-event estimation a real collision scatters whenever the
      // mixture scatters at all (docs/mis.md "No absorption events"): the
      // collision estimator has collected the emission here already, and
      // β · σs/(σa + σs) keeps the expectation.
      const bool survive = w.ws.lights.active() && collision_estimator && sigma_s > 0.0;
      if (w.scatters == 0 && u < sigma_a + sigma_s) w.feature(sigma_s / (sigma_a + sigma_s), glm::dvec3(0.0), t);
      if (!survive && u < sigma_a) {
        ++w.cnt.collisions;
        return w.ended(collision_estimator ? w.L : w.beta * emitted_at(md, c, x, s) / sigma_a);
      }
      if (!(u < sigma_a + sigma_s)) continue;  // null collision
      ++w.cnt.collisions;
      return scatter_at(w, x, u, sigma_a, sigma_s, survive);
    }
  }
  return Flight::Reached;
}

// The ray reached a surface: a Lambertian bounce, next-event estimation and
// the continuation. false: the walk has ended (w.result).
bool surface_bounce(Walk& w, const geometry::SurfaceHit& hit) {
  const WalkScene& ws = w.ws;
  const WalkLights& lights = ws.lights;
  ++w.cnt.collisions;
  const double albedo = geometry::albedo_at(ws.surfaces, hit)[w.c];
  const glm::dvec3 n_f = glm::dot(hit.normal, w.d) < 0.0 ? hit.normal : -hit.normal;
  if (w.scatters == 0) w.feature(albedo, n_f, hit.t);
  if (w.scatters == w.max_depth) return w.end(ws.collision_estimator ? w.L : 0.0);
  ++w.scatters;
  w.first_vertex(WalkAov::Vertex::Surface);
  if (!(w.beta * albedo > 0.0)) return w.end(w.L);  // black surface: nothing more can arrive
  w.o = geometry::offset_ray_origin(hit.position, n_f);
  auto lambert = [&](const glm::dvec3& dir) {
    const double cos_theta = std::max(0.0, glm::dot(n_f, dir));
    return VertexLobe{albedo * cos_theta / std::numbers::pi, cos_theta / std::numbers::pi};
  };
  const int n_surface = lights.selection.surface_light_samples;  // next-event samples per vertex
  if (lights.active()) w.L += w.beta * next_event(ws, w.c, w.o, lambert, n_surface, w.rng, w.cnt, w.s);
  double weight;
  Pcg32& rng = w.rng;
  if (!continue_from(ws, w.o, lambert,
                     [&] { return sample_cosine_hemisphere(n_f, {rng.uniform(), rng.uniform()}).direction; },
                     n_surface, rng, w.d, weight, w.mis))
    return w.end(w.L);
  w.beta *= weight;
  if (lights.active() && lights.selection.ratio_tracked_continuation) {
    // docs/mis.md "Ratio-tracked continuation": what this ray would collect
    // before its next real event, I(o, d), comes from a light ray along d
    // with the continuation's weight and MIS weight; the path collects
    // nothing on that segment (emission or sky) and goes on as before.
    w.L += w.beta * unidirectional_weight(lights, w.mis) *
           walk_channel(ws, w.c, w.o, w.d, w.rng, w.cnt, w.s.light_ray(), 0, WalkRole::LightRay);
    w.skip_segment = true;
  }
  return true;
}

}  // namespace

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
  Walk w(ws, c, rng, cnt, s, max_depth, role, camera_escaped, role == WalkRole::Path ? aov : nullptr, o, d);
  const WalkLights& lights = ws.lights;
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (;;) {
    // The closest surface bounds this segment.
    geometry::SurfaceHit hit;
    const bool hit_surface = !ws.surfaces.empty() && geometry::intersect(ws.surfaces, geometry::Ray{w.o, w.d}, inf, hit);
    // A sphere light in front of it ends the segment instead (opaque).
    const SphereLightHit sphere = intersect_sphere_lights(lights, w.o, w.d, hit_surface ? hit.t : inf);
    const double t_surf = sphere.light >= 0 ? sphere.t : hit_surface ? hit.t : inf;
    // The weight of what this ray finds before its next event.
    const double w_ray = w.skip_segment ? 0.0 : unidirectional_weight(lights, w.mis);
    w.skip_segment = false;
    const Flight flight = track_media(w, t_surf, w_ray);
    if (flight == Flight::Ended) return w.result;
    if (flight == Flight::Scattered) continue;
    // A sphere light absorbs the ray and adds its radiance, weighted like the
    // environment's (docs/lights.md "Sampling"); black from inside.
    if (sphere.light >= 0) {
      const double seen = sphere.outside ? w.beta * w_ray * lights.analytic[sphere.light].value[c] : 0.0;
      if (w.scatters == 0 && w.aov) {
        const glm::dvec3 x = w.o + sphere.t * w.d;
        w.aov->direct = seen;
        w.feature(0.0, glm::normalize(x - lights.analytic[sphere.light].light.center), sphere.t);
      }
      return w.L + seen;
    }
    if (!hit_surface) {
      if (role == WalkRole::Path && w.scatters == 0) {  // the camera ray itself: alpha, transparency
        if (camera_escaped) *camera_escaped = true;
        if (ws.transparent) return w.L;
      }
      const double seen = w.beta * w_ray * ws.escaped(w.d, c);
      if (w.scatters == 0 && w.aov) w.aov->direct = seen;
      return w.L + seen;
    }
    if (!surface_bounce(w, hit)) return w.result;
  }
}

}  // namespace pyrolume::cpu
