#pragma once
// Which lights next-event estimation samples, with what probability, and how
// its samples are combined with BSDF/phase sampling (docs/mis.md). Shared by
// both backends so they make the same choices.
#include <string>
#include <vector>

#include "scene/Scene.h"

namespace pyrolume {

class EnvironmentMap;
class EmissionCdf;

// How emission from sampleable lights is estimated.
enum class LightStrategy {
  Bsdf,       // BSDF/phase sampling only (integrator.mis false, or nothing to sample)
  Mis,        // both strategies, power heuristic
  LightOnly,  // debug (integrator.light_only): next-event estimation only
};

// "bsdf" | "mis" | "light_only"
const char* strategy_name(LightStrategy k);

// Which kinds of light next-event estimation may sample, from the scene's keys
// alone (before any light is built; a backend builds emission CDFs only for
// `media`). Empty with "mis": false, the absorption estimator or max_depth 0.
//   "mis" absent (the default): the environment map where something can be
//     lit by it (surfaces or scattering media), the emissive grids only where
//     there are surfaces: a fire alone lights only itself, and light sampling
//     its own emission for its in-scattering costs more than it saves
//     (docs/mis.md "When light sampling runs by default").
//   "mis": true or "light_only": true: both, wherever something scatters.
//   The scene's `lights` wherever something can be lit (they are reached
//     only by light sampling: "mis": false contradicts them).
struct LightCandidates {
  bool environment = false;
  bool media = false;
  bool lights = false;
};
LightCandidates light_candidates(const Scene& scene);

// With next-event estimation, the share of continuations drawn from the
// vertex's own lobe unless integrator.guided_continuation says otherwise
// (docs/mis.md "Guided continuation": all of them, since drawing half from
// the lights no longer paid at equal time once light sampling got cheaper).
inline constexpr double kContinueOwn = 1.0;

struct LightSelection {
  // Probability that one next-event sample picks the environment map.
  double p_env = 0.0;
  // Per scene medium: probability of picking its emission CDF (0: not a light).
  std::vector<double> p_medium;
  // Per entry of Scene::lights: probability of picking it.
  std::vector<double> p_light;
  LightStrategy strategy = LightStrategy::Bsdf;
  // What both backends render with (choose_emission_estimator).
  EmissionEstimator estimator = EmissionEstimator::Absorption;
  // With next-event estimation, the probability that a vertex's continuation
  // is drawn from its own lobe; otherwise from the lights, by the same
  // distribution as next-event estimation (docs/mis.md "Guided continuation").
  double p_continue_own = 1.0;
  // Next-event samples at each surface vertex (integrator.surface_light_samples;
  // medium vertices take one). MIS weighs their n·p_light against the
  // continuation's pdf (docs/mis.md "Several light samples").
  int surface_light_samples = 1;
  // At each surface vertex, what the continuation finds before its first real
  // event is collected by a ratio-tracked ray along the same direction instead
  // of by the path (integrator.ratio_tracked_continuation; docs/mis.md
  // "Ratio-tracked continuation").
  bool ratio_tracked_continuation = false;

  bool any() const;
  // The continuation's solid-angle pdf of a direction that the vertex's lobe
  // draws with p_own and the lights with p_light (docs/mis.md eq. 5).
  double continuation_pdf(double p_own, double p_light) const {
    return p_continue_own * p_own + (1.0 - p_continue_own) * p_light;
  }
};

// The emission estimator is chosen here and only here: these two functions
// are the only readers of integrator.emission_estimator's choice. The
// scene's estimator when it names one; for "auto", the line estimator where
// it collects some medium, else the collision estimator with light sampling
// (what MIS is written for) and the absorption estimator without (the
// fastest for BSDF/phase sampling).
//
// Which emitting media the line estimator collects (line_media in
// host/render/LineEstimator.h applies it): none when the scene names another
// estimator, every emitting medium when it names "line", and for "auto" the
// thin ones that give a fair share of the emitted power.
enum class LineMediaRule { None, EveryEmitting, Thin };
LineMediaRule line_media_rule(const Integrator& in);
// line_media: the line estimator collects some medium (LineMedia::any).
EmissionEstimator choose_emission_estimator(const Integrator& in, bool line_media, LightStrategy strategy);

// env: the loaded environment map or null; cdfs: per scene medium, its emission
// CDF or null (homogeneous media and grids that emit nothing are not lights).
// Only the kinds light_candidates allows are sampled: every other light gets
// probability 0, so a backend that built it anyway still agrees.
//
// Continuation: p_continue_own = 1 − integrator.guided_continuation (unset:
// kContinueOwn) with next-event estimation, 1 without.
//
// Choice between lights (docs/lights.md "Choosing a light"): two groups, the
// lights at infinity (the environment, distant lights) and the lights in the
// scene (emissive media; point, spot and sphere lights). Their powers have
// different units (per unit area against watts), so their ratio means
// nothing without a distance: each group that has a light gets 1/2 (1 when it
// is alone). Within a group, by power: the environment ∫Y dω against a
// distant light's irradiance Y(E); an emissive medium's 4π ∫ w dV
// (EmissionCdf::power) against light_power's watts.
//
// Strategy: Mis (LightOnly with integrator.light_only) when at least one light
// is sampled, otherwise Bsdf. Estimator: choose_emission_estimator, with
// line_media telling whether the line estimator collects some medium
// (line_media() in host/render/LineEstimator.h). Throws std::invalid_argument
// for integrator keys that contradict each other (integrator_conflict; the
// loader refuses such files).
LightSelection select_lights(const Scene& scene, const EnvironmentMap* env, const std::vector<const EmissionCdf*>& cdfs,
                             bool line_media = false);

// Power heuristic, β = 2 (Veach 1997, eq. 9.13), for the strategy with pdf
// p_this against p_other; 1 when p_other is 0.
inline double power_heuristic(double p_this, double p_other) {
  const double a = p_this * p_this, b = p_other * p_other;
  return a + b > 0.0 ? a / (a + b) : 0.0;
}

}  // namespace pyrolume
