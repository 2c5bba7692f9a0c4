#pragma once
// Which lights next-event estimation samples, with what probability, and how
// its samples are combined with BSDF/phase sampling (docs/mis.md). Shared by
// both backends so they make the same choices.
#include <string>
#include <vector>

#include "scene/Scene.h"
#include "shared/light_types.h"

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

// The share of the static choice (p_env, p_medium below) in the choice
// between lights seen from a receiver (LightSelection::choice_at): it keeps
// every light's probability at least this fraction of its static one, so a
// light the receiver-aware estimate misjudges is still sampled. One value for
// both renderers (shaders/shared/light_types.h).
inline constexpr double kLightChoiceStaticShare = double(gpu::LIGHT_CHOICE_STATIC_SHARE);

struct LightSelection {
  // The static choice: probability that one next-event sample picks the
  // environment map, and per scene medium its emission CDF (0: not a light).
  double p_env = 0.0;
  std::vector<double> p_medium;
  // What the choice seen from a receiver weighs: the environment's irradiance
  // on a flat receiver, E_env = ∫ Y(L_env) dω / 4 (EnvironmentMap::power;
  // LIGHT_CHOICE_ENV_IRRADIANCE_PER_POWER), and per medium its power
  // Φ_j = ∫ w dV (EmissionCdf::power); 0 where that light is not a light.
  double env_irradiance = 0.0;
  std::vector<double> medium_power;
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
  // The choice seen from receiver o (docs/mis.md "Choosing the light"), given
  // each medium's emission-CDF normaliser norm[j] = EmissionCdf::receiver_norm(o)
  // (Σ_s Φ_s/Φ_j / max(|o − c_s|², r_s²); 0 where not a light). Each light's
  // irradiance at o on a flat receiver facing it, ignoring occlusion and
  // extinction, is estimated as E_env = env_irradiance and
  // E_j = medium_power[j]·norm[j] (both luminance × solid angle), and
  //   P(light) = a·P_static(light) + (1 − a)·E_light / Σ E,   a = kLightChoiceStaticShare.
  // Writes p_medium_at[j] for every medium and returns the environment's.
  double choice_at(const std::vector<double>& norm, std::vector<double>& p_medium_at) const;
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
// Static choice between lights: the environment and the emissive media get
// 1/2 each when both exist (their powers, ∫Y dω and ∫Y(σa Le) dV, have
// different units, so their ratio means nothing without a distance); among the
// emissive media, by power ∫ w dV (EmissionCdf::power). The renderers mix it
// with a receiver-aware choice that supplies the distance (choice_at).
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
