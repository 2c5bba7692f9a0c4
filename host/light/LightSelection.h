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

// With next-event estimation, the share of continuations drawn from the
// vertex's own lobe (docs/mis.md "Guided continuation": the best of 1, 1/2
// and 1/4 on terrain_explosion).
inline constexpr double kContinueOwn = 0.5;

struct LightSelection {
  // Probability that one next-event sample picks the environment map.
  double p_env = 0.0;
  // Per scene medium: probability of picking its emission CDF (0: not a light).
  std::vector<double> p_medium;
  LightStrategy strategy = LightStrategy::Bsdf;
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

// env: the loaded environment map or null; cdfs: per scene medium, its emission
// CDF or null (homogeneous media and grids that emit nothing are not lights).
//
// Continuation: p_continue_own = kContinueOwn with next-event estimation, 1 without.
//
// Choice between lights: the environment and the emissive media get 1/2 each
// when both exist (their powers, ∫Y dω and ∫Y(σa Le) dV, have different units,
// so their ratio means nothing without a distance); among the emissive media,
// by power ∫ w dV (EmissionCdf::power).
//
// Strategy: Mis or LightOnly needs integrator.mis, the collision emission
// estimator (what the renderers' MIS is written and tested for; docs/mis.md),
// max_depth ≥ 1 and at least one light.
LightSelection select_lights(const Scene& scene, const EnvironmentMap* env, const std::vector<const EmissionCdf*>& cdfs);

// One line for stderr when the scene file asks for MIS ("mis": true written
// out) but cannot get it with the absorption estimator (empty: none).
std::string light_strategy_warning(const Scene& scene);

// Power heuristic, β = 2 (Veach 1997, eq. 9.13), for the strategy with pdf
// p_this against p_other; 1 when p_other is 0.
inline double power_heuristic(double p_this, double p_other) {
  const double a = p_this * p_this, b = p_other * p_other;
  return a + b > 0.0 ? a / (a + b) : 0.0;
}

}  // namespace pyrolume
